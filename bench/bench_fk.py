"""Forward-kinematics benchmark: fast vs exhaustive vs vvcm-rs, one process, one run.

Usage::

    python bench/bench_fk.py [--quick] [--json OUT]

Measures, on this machine and in this process:

* single-formation latency of ``method="fast"`` on the FK paper's Examples 1-5 and on
  random convex teams of N = 4, 8, 10, 20, 50, 200, 1000 robots;
* ``method="exhaustive"`` (the paper's Algorithm 1) where it finishes in reasonable time;
* vvcm-rs (PyPI ``vvcm-rs``: Rust, float32, exhaustive) on the same inputs when installed;
* batched throughput (formations/s) for N = 4 and N = 8;
* the authors' MATLAB code run times (measured under Octave, from the reference data).

Ratios are reported against the baselines measured in the same run. Timing: the best
of several repeats of a loop that runs for at least ``min_time`` seconds.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from taut.sheet import Sheet, forward_kinematics, forward_kinematics_batch
from taut.sheet.random import random_team

REFERENCE = Path(__file__).resolve().parent.parent / "tests" / "data" / "vvcm_reference_outputs.json"

try:
    import vvcm_rs
except ImportError:  # pragma: no cover - optional
    vvcm_rs = None


def timeit(fn, min_time=0.3, repeats=3):
    """Best mean time per call (s) over ``repeats`` loops of >= ``min_time`` seconds."""
    fn()
    best = np.inf
    for _ in range(repeats):
        n, start = 0, time.perf_counter()
        while True:
            fn()
            n += 1
            elapsed = time.perf_counter() - start
            if elapsed >= min_time:
                break
        best = min(best, elapsed / n)
    return best


def vvcm_timer(sheet, formation, hold):
    engine = vvcm_rs.VvcmFk(float(hold), np.asarray(sheet.vertices, dtype=np.float32))
    f32 = np.asarray(formation, dtype=np.float32)
    return lambda: engine.update_stable_solutions(f32)


def cases(quick):
    ref = json.loads(REFERENCE.read_text())["examples"]
    for name in ("example1", "example2_r2_r4_at_353mm", "example3_zr1000",
                 "example4_r1_at_52_13cm_zr1000", "example5_zr1000"):
        e = ref[name]
        yield (name, Sheet(e["Vn_mm"]), np.array(e["Rn_mm"], float), float(e["zr_mm"]),
               e["wall_time_s"])
    rng = np.random.default_rng(2026)
    for n in (4, 8, 10, 20, 50, 200) + (() if quick else (1000,)):
        sheet, formation = random_team(n, rng)
        yield f"random N={n}", sheet, formation, 2.0 * sheet.size, None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="shorter timing, skip N=1000")
    ap.add_argument("--json", help="also write the results to this file")
    args = ap.parse_args(argv)
    min_time = 0.1 if args.quick else 0.3
    rows = []
    print(f"vvcm-rs: {'installed ' + vvcm_rs.__version__ if vvcm_rs else 'not installed'}")
    print(f"{'case':32s} {'N':>5s} {'fast ms':>9s} {'exh. ms':>9s} {'vvcm ms':>9s} "
          f"{'x vvcm':>7s} {'x exh.':>7s} {'x octave':>9s} sols")
    for name, sheet, formation, hold, octave in cases(args.quick):
        n = sheet.n
        fast = timeit(lambda: forward_kinematics(sheet, formation, hold), min_time)
        sols = len(forward_kinematics(sheet, formation, hold).equilibria)
        exh = None
        if n <= 15:
            exh = timeit(lambda: forward_kinematics(sheet, formation, hold, method="exhaustive"),
                         min_time, repeats=1 if n > 10 else 3)
        vv = None
        if vvcm_rs is not None and n <= 20:
            vv = timeit(vvcm_timer(sheet, formation, hold), min_time)
        row = dict(case=name, N=n, fast_ms=fast * 1e3, exhaustive_ms=None if exh is None else exh * 1e3,
                   vvcm_ms=None if vv is None else vv * 1e3, octave_s=octave, solutions=sols)
        rows.append(row)

        def fmt(x):
            return f"{x * 1e3:9.3f}" if x is not None else f"{'-':>9s}"

        def ratio(x, width=7):
            return f"{x / fast:{width}.1f}" if x is not None else f"{'-':>{width}s}"

        print(f"{name:32s} {n:5d} {fmt(fast)} {fmt(exh)} {fmt(vv)} {ratio(vv)} {ratio(exh)} "
              f"{ratio(octave, 9)} {sols}")
        sys.stdout.flush()

    print("\nbatched throughput (forward_kinematics_batch, hold height 2 x sheet size):")
    rng = np.random.default_rng(7)
    for n, batch in ((4, 20000), (8, 4000)):
        sheet, formation = random_team(n, rng)
        forms = formation[None] + rng.normal(scale=0.002 * sheet.size, size=(batch, n, 2))
        d = np.linalg.norm(forms[:, :, None] - forms[:, None], axis=3)
        forms = forms[np.all(d <= sheet.side_lengths(), axis=(1, 2))]
        per = timeit(lambda: forward_kinematics_batch(sheet, forms, 2 * sheet.size),
                     min_time, repeats=2)
        single = timeit(lambda: forward_kinematics(sheet, forms[0], 2 * sheet.size), min_time)
        rate = len(forms) / per
        print(f"  N={n}: {rate:,.0f} formations/s batched ({len(forms)} per call); "
              f"{1 / single:,.0f}/s one at a time ({rate * single:.1f}x)")
        rows.append(dict(case=f"batch N={n}", N=n, formations_per_s=rate,
                         single_per_s=1 / single))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
