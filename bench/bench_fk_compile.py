"""First-call cost of the compiled FK kernel: compilation, then the on-disk cache.

Usage::

    python bench/bench_fk_compile.py

Runs three fresh Python processes with ``NUMBA_CACHE_DIR`` pointing to a new, empty
directory and ``TAUT_NUMBA=always``: the first compiles every kernel function (numba,
``cache=True``), the second and third load them from that directory. Each reports the time of ``import taut.sheet``
and of the first ``FKSolver.solve``, ``solve_batch`` and ``Simulator.step`` calls (wall
seconds; the machine may be loaded by other work, so run it twice).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

CHILD = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import taut.sheet as ts
t1 = time.perf_counter()
team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0)
solver = ts.FKSolver(team)
solver.solve([[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]]).equilibria
t2 = time.perf_counter()
solver.solve_batch(np.array([[[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]]] * 2))
t3 = time.perf_counter()
sim = ts.Simulator(team, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]], dt=0.1)
sim.step(velocities=np.tile([0.01, 0.0], (4, 1)))
t4 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "first_solve_s": t2 - t1, "first_batch_s": t3 - t2,
                  "first_step_s": t4 - t3, "cpu_s": time.process_time(),
                  "backend": solver.backend}))
"""


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        # always: the default (auto) would answer with numpy on the empty cache and compile
        # in a background warmup (docs/compiled_kernels.md), measuring no compilation
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, TAUT_NUMBA="always")
        for label in ("compile (empty cache)", "cached, new process", "cached, new process"):
            out = subprocess.run([sys.executable, "-c", CHILD], env=env, check=True,
                                 capture_output=True, text=True).stdout
            r = json.loads(out)
            files = sum(len(f) for _, _, f in os.walk(cache))
            print(f"{label:24s} import {r['import_s']:.2f} s, first solve "
                  f"{r['first_solve_s']:.2f} s, first batch {r['first_batch_s']:.2f} s, "
                  f"first Simulator.step {r['first_step_s']:.2f} s; process CPU "
                  f"{r['cpu_s']:.1f} s "
                  f"({r['backend']}; {files} cache files)")


if __name__ == "__main__":
    main()
