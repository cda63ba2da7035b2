"""Benchmark of the mobile-CDPR motion analyses (taut.cdpr.sets.twist / redundancy / deploy) on
the FASTKIT preset.

Measures, in one run on this machine:
  * exact available twist set (task mode, active base moving: 330 zonotope facet pairs in
    R^8), batched, poses/s;
  * axis twist capacities (Fig. 13), ray shooting in the batched H-rep vs one HiGHS LP per
    pose and direction over the joint rates (the two must agree), poses/s;
  * redundancy resolution (LP feasibility + SLSQP), twists/s;
  * one deployment plan for a 5 m x 0.1 m x 0.8 m box, s.
Run: ``python bench/bench_cdpr_motion.py [--poses 2000]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from taut.cdpr import with_stabilisers
from taut.cdpr import plan_deployment
from taut.cdpr import resolve_redundancy
from taut.cdpr import available_twist_set, twist_capacities
from taut.io.cdpr_model import load_cdpr_model


def poses_in(robot, n, seed=0, angle=0.1):
    g = np.random.default_rng(seed)
    lo = np.array([-2.3, -0.2, 0.3])
    hi = np.array([2.3, 0.2, 1.6])
    return np.column_stack([g.uniform(lo, hi, (n, 3)), g.uniform(-angle, angle, (n, 3))])


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=2000)
    ap.add_argument("--lp-poses", type=int, default=50)
    args = ap.parse_args()
    robot = load_cdpr_model("fastkit")
    P = poses_in(robot, args.poses)
    Q = P[: args.lp_poses]
    available_twist_set(robot, P[:10])                   # warm-up (subset tables, BLAS)
    t_ats, _ = timed(lambda: available_twist_set(robot, P))
    t_h, ch = timed(lambda: twist_capacities(robot, P))
    t_lp, cl = timed(lambda: twist_capacities(robot, Q, method="lp"))
    err = max(np.abs(ch.positive[: len(Q)] - cl.positive).max(),
              np.abs(ch.negative[: len(Q)] - cl.negative).max())
    g = np.random.default_rng(1)
    T = g.normal(size=(200, 6)) * [0.5, 0.5, 0.5, 0.3, 0.3, 0.3]
    t_rr, res = timed(lambda: [resolve_redundancy(robot, P[i % len(P)], t)
                               for i, t in enumerate(T)])
    feas = np.mean([r.success for r in res])
    box = [[-2.5, -0.05, 0.2], [2.5, 0.05, 1.0]]
    t_dep, dep = timed(lambda: plan_deployment(with_stabilisers(robot), box,
                                               required_twist=[1.0, 0, 0, 0, 0, 0],
                                               maxiter=3, popsize=5, grid=(6, 2, 3),
                                               verify_grid=(11, 3, 5)))
    print(f"model {robot.name}: {robot.m} cables, task mode with the active base moving")
    print(f"  available twist set, batched {len(P):>6} poses: {len(P) / t_ats:10,.0f} poses/s")
    print(f"  axis capacities, H-rep rays  {len(P):>6} poses: {len(P) / t_h:10,.0f} poses/s")
    print(f"  axis capacities, HiGHS LPs   {len(Q):>6} poses: {len(Q) / t_lp:10,.0f} poses/s"
          f"   (max |difference| {err:.1e})")
    print(f"  redundancy resolution        {len(T):>6} twists: {len(T) / t_rr:10,.0f} twists/s"
          f"   ({feas:.0%} feasible)")
    print(f"  deployment plan (5 x 0.1 x 0.8 m box): {t_dep:.1f} s, {dep.evaluations} "
          f"placements, feasible={dep.success}, margin {dep.margin:.3f}")


if __name__ == "__main__":
    main()
