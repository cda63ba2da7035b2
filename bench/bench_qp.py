"""Per-pose cost of the minimum-norm tension QP: DAQP (taut._qp) against SciPy's SLSQP (the
fallback) and, where it applies (at most 2 redundant cables), the batched exact KKT
enumeration, through ``distribute_tensions(..., "qp_min_norm", qp_solver=...)``.

Robots: the FASTKIT preset (8 cables, 2 redundant; tipping on) and a 12-cable fixed frame
(6 redundant; tests/cdpr/cdpr_helpers.py). Same random poses for every solver, runs
interleaved and repeated; medians and [min, max] of the time per pose, and how many poses
each solver finds feasible (DAQP and the enumeration match the LP exactly; SLSQP may miss).

    python bench/bench_qp.py [--poses 200] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "cdpr"))

from cdpr_helpers import random_poses, twelve_cable_robot  # noqa: E402

from taut.cdpr import distribute_tensions  # noqa: E402
from taut.io.cdpr_model import load_cdpr_model  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cases = {"fastkit (8 cables, r = 2)": (load_cdpr_model("fastkit"), {},
                                           ("enumeration", "daqp", "scipy")),
             "12 cables (r = 6)": (twelve_cable_robot(), {"margin": 0.2}, ("daqp", "scipy"))}
    for name, (robot, kw, solvers) in cases.items():
        P = random_poses(robot, args.poses, seed=1, **kw)
        lp = distribute_tensions(robot, P, "lp_min_sum").success
        times: dict[str, list[float]] = {s: [] for s in solvers}
        found: dict[str, int] = {}
        distribute_tensions(robot, P[:2], "qp_min_norm", qp_solver="daqp")      # warm up
        for _ in range(args.repeat):                                             # interleaved
            for s in solvers:
                t0 = time.perf_counter()
                res = distribute_tensions(robot, P, "qp_min_norm", qp_solver=s)
                times[s].append((time.perf_counter() - t0) / len(P))
                found[s] = int(res.success.sum())
        print(f"{name}: {len(P)} poses, LP-feasible {int(lp.sum())}")
        ref = statistics.median(times["scipy"])
        for s in solvers:
            med = statistics.median(times[s])
            print(f"  {s:<12} {1e6 * med:9.1f} us/pose [{1e6 * min(times[s]):.1f}, "
                  f"{1e6 * max(times[s]):.1f}]  {ref / med:6.1f}x SLSQP  feasible {found[s]}")


if __name__ == "__main__":
    main()
