"""A quick CLI: what `taut fk` imports, and its start-up cost as a ratio to
``python -c "import numpy"`` measured in the same run (issue 27; bench/bench_startup.py
measures the absolute times)."""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent.parent
EXAMPLE1 = str(ROOT / "examples" / "sheet" / "example1.yaml")
#: Modules `taut fk` (no --plot) must not load: other domains, figures, numba (a
#: one-shot FK answers with numpy: taut._jit.prefer_compiled) and scipy's optimisers.
NOT_FOR_FK = ("matplotlib", "shapely", "numba", "scipy.optimize", "taut.plan", "taut.cdpr",
              "taut.viz", "taut.sweep", "taut.physics", "taut.app", "taut.io.plan_scenario",
              "taut.io.cdpr_model", "taut.sheet.ik", "taut.sheet._kernels", "rich")
#: Start-up budgets as multiples of the process CPU time of `python -c "import numpy"`
#: (minimum of interleaved runs). Measured: --version 1.4-1.6x, fk 3.2-4.3x on an idle and
#: on a loaded 2-core machine; importing matplotlib alone adds about 2.5x, numba 2x.
VERSION_BUDGET = 2.5
FK_BUDGET = 5.5


def _loaded(args: list[str], env: dict[str, str] | None = None) -> list[str]:
    code = ("import json, sys, taut.cli\n"
            f"code = taut.cli.main({args!r})\n"
            "print(json.dumps(sorted(sys.modules)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=300, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _heavy(modules: list[str]) -> list[str]:
    return [m for m in NOT_FOR_FK if m in modules or any(x.startswith(m + ".")
                                                         for x in modules)]


def test_fk_loads_only_what_fk_needs(tmp_path):
    env = dict(os.environ, TAUT_NUMBA="auto", NUMBA_CACHE_DIR=str(tmp_path))
    # A fresh lock: the cold process starts no background warmup (one would compile every
    # kernel into tmp_path, ~65 s of CPU outliving the test). The stamp's path does not
    # depend on TAUT_NUMBA; asked with "never", the asking process starts none either.
    stamp = subprocess.run([sys.executable, "-c", "import taut._jit as j; print(j.stamp_path())"],
                           env=dict(env, TAUT_NUMBA="never"), capture_output=True, text=True,
                           check=True).stdout
    Path(stamp.strip() + ".lock").write_text("0")
    assert _heavy(_loaded(["fk", EXAMPLE1], env)) == []
    assert _heavy(_loaded(["fk", EXAMPLE1])) == []            # the suite's: TAUT_NUMBA=always
    assert _heavy(_loaded(["--version"])) == []
    plot = str(tmp_path / "fk.png")
    assert "matplotlib" in _heavy(_loaded(["fk", EXAMPLE1, "--plot", plot]))   # the check sees


def _cpu(args: list[str]) -> float:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, timeout=300,
                   check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


# A timing bound (~3.5 s of CPU in interleaved interpreter starts): the slow target, which
# CI runs, like the app's latency bound; test_fk_loads_only_what_fk_needs stays fast.
@pytest.mark.slow
def test_startup_budget_as_a_ratio_to_importing_numpy():
    runs: dict[str, list[float]] = {"numpy": [], "version": [], "fk": []}
    cmds = {"numpy": ["-c", "import numpy"], "version": ["-m", "taut", "--version"],
            "fk": ["-m", "taut", "fk", EXAMPLE1]}
    for _ in range(5):                                    # interleaved
        for name, args in cmds.items():
            runs[name].append(_cpu(args))
    base = min(runs["numpy"])
    ratios = {name: min(v) / base for name, v in runs.items()}
    assert ratios["version"] <= VERSION_BUDGET, ratios
    assert ratios["fk"] <= FK_BUDGET, ratios
