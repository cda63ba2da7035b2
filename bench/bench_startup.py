"""Cold and warm starts of the ``taut`` command, before (a clone of a git revision) and
after (this working tree), in one run (issue 27; docs/compiled_kernels.md).

Usage::

    python bench/bench_startup.py [--repeat 3] [--before HEAD] [--warm 3]

Every process is a fresh ``python`` with the venv's interpreter. *Cold* is a fresh
clone: each cold round copies the side's ``src`` into a new directory without any
``__pycache__`` (no bytecode of taut, no machine code, no stamp; the installed packages
keep the bytecode ``pip`` wrote) and points ``NUMBA_CACHE_DIR`` at a new, empty directory.
For the working tree two routes are measured from empty caches:

* **README** (``make``): the install step runs ``taut compile``; then the first
  ``taut fk`` and the first ``taut plan``;
* **pip** (a plain ``pip install``, no install step): the first ``taut fk`` and, from
  another empty cache, the first ``taut plan``; both run the numpy engines and start the
  background warmup, which this script then stops (its pid is in the lock file).

The *before* revision (default ``HEAD``) is ``git clone``d into a temporary directory and
run with ``PYTHONPATH`` pointing at its ``src``. Warm runs reuse each side's filled caches.
Rounds are interleaved (before, after, peers) and repeated; the table gives medians and
the spread (min-max) of wall seconds, and the median CPU seconds of the process (user +
sys, less sensitive to other load on the machine). ``uptime`` is printed at the start and
the end.
"""

from __future__ import annotations

import argparse
import glob
import os
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FK = ["fk", "examples/sheet/example1.yaml"]
PLAN = ["plan", "examples/plan/paper_corridor.yaml"]
#: One FK of Example 1 by vvcm-rs in a new process (import and solve), the peer's floor.
VVCM_RS = ("import numpy as np, vvcm_rs\n"
           "e = vvcm_rs.VvcmFk(800.0, np.array([[-320, -420], [800, -380], [750, 710], "
           "[-370, 660]], np.float32))\n"
           "e.update_stable_solutions(np.array([[210, 120], [800, 40], [900, 550], "
           "[440, 720]], np.float32)).stable()\n")


def run(args: list[str], env: dict[str, str], cwd: Path = ROOT) -> tuple[float, float]:
    """Wall and CPU seconds of one process run in ``cwd`` (fails loudly on a traceback or
    a non-zero exit but 1, a valid "no" answer)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, *args], env=env, cwd=cwd, capture_output=True,
                         text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # Python's own crash exits 1 too: a traceback is a failure whatever the code (a broken
    # "before" revision, f552908, once passed for a 0.9 s "first plan" this way).
    if out.returncode not in (0, 1) or "Traceback (most recent call last)" in out.stderr:
        raise SystemExit(f"{args} failed ({out.returncode}): {out.stderr.strip()[-400:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def stop_warmup(cache: str) -> None:
    """Stop the background warmup a cold command started (its pid is in the lock)."""
    for lock in glob.glob(os.path.join(cache, "taut-jit-*.lock")):
        try:
            pid = int(Path(lock).read_text().strip() or 0)
            if pid > 0:
                os.killpg(pid, signal.SIGTERM)   # its own session: the warmup and children
        except (OSError, ValueError):
            pass


class Side:
    """One code base (``root``: its ``src`` and ``examples``) with its caches."""

    def __init__(self, name: str, root: Path, tmp: str) -> None:
        self.name, self.root, self.tmp = name, root, tmp
        self.warm_env: dict[str, str] = {}

    def fresh_env(self) -> dict[str, str]:
        """The environment of a fresh clone: a copy of ``src`` without caches."""
        src = Path(tempfile.mkdtemp(dir=self.tmp)) / "src"
        shutil.copytree(self.root / "src", src,
                        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        env = dict(os.environ, NUMBA_CACHE_DIR=tempfile.mkdtemp(dir=self.tmp),
                   PYTHONPATH=str(src))
        for name in ("TAUT_NUMBA", "TAUT_DISABLE_NUMBA", "PYTHONDONTWRITEBYTECODE",
                     "PYTHONPYCACHEPREFIX"):
            env.pop(name, None)              # as on a user's machine: bytecode is cached
        return env


def round_before(side: Side, rec: dict[str, list[tuple[float, float]]]) -> None:
    env = side.fresh_env()
    rec["before: first taut fk"].append(run(["-m", "taut", *FK], env, side.root))
    rec["before: first taut plan"].append(run(["-m", "taut", *PLAN], env, side.root))
    side.warm_env = env


def round_after(side: Side, rec: dict[str, list[tuple[float, float]]]) -> None:
    env = side.fresh_env()
    rec["after, README: install step (taut compile)"].append(run(["-m", "taut", "compile"], env))
    rec["after, README: first taut fk"].append(run(["-m", "taut", *FK], env))
    rec["after, README: first taut plan"].append(run(["-m", "taut", *PLAN], env))
    side.warm_env = env
    for label, cmd in (("fk", FK), ("plan", PLAN)):
        env = side.fresh_env()
        rec[f"after, pip: first taut {label}"].append(run(["-m", "taut", *cmd], env))
        stop_warmup(env["NUMBA_CACHE_DIR"])


def round_warm(sides: list[Side], rec: dict[str, list[tuple[float, float]]], k: int) -> None:
    for _ in range(k):
        for side in sides:
            env, cwd = side.warm_env, side.root
            rec[f"{side.name}: warm taut fk"].append(run(["-m", "taut", *FK], env, cwd))
            rec[f"{side.name}: warm taut plan"].append(run(["-m", "taut", *PLAN], env, cwd))
            rec[f"{side.name}: taut --version"].append(
                run(["-m", "taut", "--version"], env, cwd))
            rec[f"{side.name}: import taut.sheet"].append(
                run(["-c", "import taut.sheet"], env, cwd))
            rec[f"{side.name}: from taut.sheet import forward_kinematics"].append(
                run(["-c", "from taut.sheet import forward_kinematics"], env, cwd))
        rec["python -c 'import numpy'"].append(run(["-c", "import numpy"], sides[0].warm_env))
        try:
            rec["one-shot vvcm-rs process"].append(run(["-c", VVCM_RS], sides[0].warm_env))
        except SystemExit:
            pass                                   # vvcm-rs not installed (make bench)


def report(rec: dict[str, list[tuple[float, float]]]) -> dict[str, float]:
    med = {}
    print(f"{'':58s} {'wall median':>11s} {'(min-max)':>13s} {'CPU median':>10s}  n")
    for label, xs in rec.items():
        walls = [w for w, _ in xs]
        med[label] = statistics.median(walls)
        print(f"{label:58s} {med[label]:9.2f} s ({min(walls):5.2f}-{max(walls):5.2f}) "
              f"{statistics.median([c for _, c in xs]):8.2f} s  {len(xs)}")
    return med


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="cold rounds")
    ap.add_argument("--warm", type=int, default=2, help="warm runs of each per round")
    ap.add_argument("--before", default="HEAD", help="git revision measured as 'before'")
    opts = ap.parse_args()
    print("load:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    with tempfile.TemporaryDirectory(prefix="taut-startup-") as tmp:
        clone = Path(tmp) / "before"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        subprocess.run(["git", "-C", str(clone), "checkout", "-q", opts.before], check=True)
        before = Side("before", clone, tmp)
        after = Side("after", ROOT, tmp)
        rec: dict[str, list[tuple[float, float]]] = defaultdict(list)
        for _ in range(opts.repeat):
            round_before(before, rec)
            round_after(after, rec)
            round_warm([before, after], rec, opts.warm)
        med = report(dict(sorted(rec.items())))
    rs = med.get("one-shot vvcm-rs process", float("nan"))
    print()
    for what in ("fk", "plan"):
        warm = {side: med[f"{side}: warm taut {what}"] for side in ("before", "after")}
        first = med[f"before: first taut {what}"]
        print(f"first/warm taut {what}: before {first / warm['before']:.2f}x, "
              f"after README {med[f'after, README: first taut {what}'] / warm['after']:.2f}x, "
              f"after pip {med[f'after, pip: first taut {what}'] / warm['after']:.2f}x "
              "(goal <= 1.5x)")
    print(f"warm taut fk / one-shot vvcm-rs: before {med['before: warm taut fk'] / rs:.2f}x, "
          f"after {med['after: warm taut fk'] / rs:.2f}x (goal <= 5x; nan: vvcm-rs missing)")
    print("load:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
