"""Benchmark of the cable-robot statics (taut.cdpr) on the FASTKIT preset.

Measures, in one run on this machine:
  * tension distribution, poses/s: Pott's improved closed form and the exact min-norm QP,
    both batched, against a per-pose HiGHS LP loop (scipy.optimize.linprog);
  * wrench-feasibility test with tipping, microseconds per pose: the batched exact
    Helly/Farkas test against a per-pose LP feasibility loop;
and prints the ratios. Run: ``python bench/bench_cdpr.py [--poses 100000]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from taut.cdpr import distribute_tensions, wrench_feasible
from taut.io.cdpr_model import load_cdpr_model


def random_poses(robot, n, seed=0, angle=0.15):
    g = np.random.default_rng(seed)
    lo, hi = robot.bounds
    span = hi - lo
    pos = g.uniform(lo + 0.05 * span, hi - 0.05 * span, (n, 3))
    return np.column_stack([pos, g.uniform(-angle, angle, (n, 3))])


def best_of(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=100_000, help="batched poses")
    ap.add_argument("--lp-poses", type=int, default=500, help="poses for the LP loops")
    ap.add_argument("--model", default="fastkit")
    args = ap.parse_args()
    robot = load_cdpr_model(args.model)
    P = random_poses(robot, args.poses)
    Q = P[: args.lp_poses]

    # Tension limits only (tipping=False), as these figures were always measured; the
    # tipping-constrained case is timed below through the feasibility test.
    t_cf, cf = best_of(lambda: distribute_tensions(robot, P, "closed_form", tipping=False))
    t_qp, qp = best_of(lambda: distribute_tensions(robot, P, "qp_min_norm", tipping=False),
                       repeat=1)
    t_lp, lp = best_of(lambda: distribute_tensions(robot, Q, "lp_min_sum", tipping=False),
                       repeat=1)
    r_cf, r_qp, r_lp = len(P) / t_cf, len(P) / t_qp, len(Q) / t_lp
    agree = (cf.success[: len(Q)] == lp.success).mean()
    print(f"model {robot.name}: {robot.m} cables, {robot.dof} DoF, "
          f"{robot.n_edges} tipping edges")
    print("tension distribution (poses/s)")
    print(f"  closed form (Pott), batched {len(P):>7}: {r_cf:12,.0f}   "
          f"x{r_cf / r_lp:,.0f} vs LP loop   (goal >= 100,000)")
    print(f"  min-norm QP exact, batched {len(P):>7}: {r_qp:12,.0f}   x{r_qp / r_lp:,.0f}")
    print(f"  HiGHS LP per pose, loop    {len(Q):>7}: {r_lp:12,.0f}")
    print(f"  feasible: closed form {cf.success.mean():.3f}, QP {qp.success.mean():.3f}; "
          f"closed form = LP on {100 * agree:.1f} % of the LP sample")

    n_w = min(len(P), 20_000)
    W = P[:n_w]
    t_wf, wf = best_of(lambda: wrench_feasible(robot, W, tipping=True))
    t_wl, wl = best_of(lambda: distribute_tensions(robot, Q, "lp_min_sum", tipping=True),
                       repeat=1)
    us_wf, us_wl = 1e6 * t_wf / n_w, 1e6 * t_wl / len(Q)
    same = (wf[: len(Q)] == wl.success).mean()
    print("wrench feasibility with tipping (us/pose)")
    print(f"  exact test (vertex), batched {n_w:>5}: {us_wf:10.2f}   "
          f"x{us_wl / us_wf:,.0f} faster than LP loop   (goal <= 50)")
    print(f"  HiGHS LP per pose, loop   {len(Q):>7}: {us_wl:10.2f}")
    print(f"  agreement with the LP: {100 * same:.2f} %; feasible fraction {wf.mean():.3f}")


if __name__ == "__main__":
    main()
