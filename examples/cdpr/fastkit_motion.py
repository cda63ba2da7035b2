"""Regenerate the FASTKIT motion figures and numbers of this folder (issue 6):

* ``fastkit_twist_capacities.png``: largest pure platform velocity along +x, +y, +z and about
  them with the active base moving vs all bases fixed (task mode), like the paper's Fig. 13;
* ``fastkit_wrench_capacities.png``: largest extra force/moment along each axis with the
  mobile bases' tipping constraints ("bases moving", mobile) vs without (bases bolted like a
  fixed frame), like Fig. 14;
* ``fastkit_deployment.png``: top view of a planned deployment for the 5 m long workspace;
* ``fastkit_motion.json``: every number of the figures, plus the lift certificate of the
  5 m x 2 m box the preset assumes (z 0.2-2.2 m; the paper gives only "5 m long by 2 m
  high"), the tallest deployable box, and the same with exits 0.5 m higher.

Run: ``python examples/cdpr/fastkit_motion.py`` (about 4 minutes on an idle machine, 40 on a
loaded 2-core one: two height bisections of six planner runs each; each step is announced
on stderr with the elapsed time).
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from taut.cdpr import axis_capacities, with_stabilisers
from taut.cdpr import lift_bound, plan_deployment, tallest_workspace
from taut.cdpr import fastkit_motion_limits, twist_capacities
from taut.io.cdpr_model import load_cdpr_model
from taut.viz.cdpr_motion import plot_capacity_bars, plot_deployment

HERE = Path(__file__).resolve().parent
POSE = np.array([1.0, 0.0, 0.8, 0.0, 0.0, 0.0])     # 1 m off-centre towards the passive base
BOX = [[-2.5, -0.05, 0.2], [2.5, 0.05, 1.0]]
TWIST = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
FULL = [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]]       # 5 m x 2 m, placed by assumption
RAISE = 0.5                 # m: structures on top of the bases put the exits higher
PLAN = dict(required_twist=TWIST, maxiter=6, popsize=6, search=(1.5, 0.5, 0.6),
            grid=(6, 2, 4), verify_grid=(21, 3, 9), seed=0)


_START = time.monotonic()


def step(what: str) -> None:
    """Progress on stderr (stdout carries the JSON)."""
    print(f"[{time.monotonic() - _START:6.0f} s] {what}", file=sys.stderr, flush=True)


def rnd(a) -> list:
    return [round(float(x), 4) for x in np.ravel(a)]


def raise_exits(robot, dz: float):
    """The robot with every exit point ``dz`` higher (the frame box follows)."""
    bases = tuple(replace(b, exit_points={k: np.asarray(v) + (0.0, 0.0, dz)
                                          for k, v in b.exit_points.items()})
                  for b in robot.bases)
    return replace(robot, bases=bases, bounds=None)


def certificate(lb) -> dict:
    return {"height": round(lb.height, 4), "bound_N": round(lb.bound, 2),
            "required_N": round(lb.required, 2), "refutes": lb.refutes,
            "per_cable_N": rnd(lb.per_cable), "sample_points": len(lb.points),
            "reason": lb.explain()}


def tallest(robot) -> dict:
    """Bisection on zmax for x in [-2.5, 2.5], zmin = 0.2, up to the highest exit point."""
    top = float(robot.exits_world[:, 2].max())
    step(f"tallest deployable box (bisection up to {top:.2f} m)")
    tw = tallest_workspace(robot, [FULL[0], [FULL[1][0], FULL[1][1], top]], tol=0.05,
                           **PLAN)
    dep = tw.deployment
    out = {"searched_up_to": top, "height": None if dep is None else round(tw.height, 4),
           "certified_limit": round(tw.certified_limit, 4),
           "certificate_at_limit": certificate(tw.certificate),
           "failed_at": None if np.isnan(tw.failed_below) else round(tw.failed_below, 4),
           "tried": [[round(z, 4), ok] for z, ok in tw.tried]}
    if dep is not None:
        out.update({"base_poses": {k: rnd(v) for k, v in dep.base_poses.items()},
                    "margin": round(dep.margin, 4), "twist_margin": round(dep.twist_margin, 4),
                    "points": len(dep.points)})
    return out


def main() -> None:
    step("twist and wrench capacities")
    robot = load_cdpr_model("fastkit")
    lim = fastkit_motion_limits()
    mv = twist_capacities(robot, POSE, lim, "task")          # active base moving
    fx = twist_capacities(robot, POSE, lim, "task", ())      # all bases fixed
    nav = twist_capacities(robot, POSE, lim, "navigation")
    plot_capacity_bars({"active base moving": mv.positive, "bases fixed": fx.positive},
                       mv.labels, ["m/s"] * 3 + ["rad/s"] * 3,
                       "FASTKIT twist capacity at (1, 0, 0.8) m (cf. Fig. 13)",
                       HERE / "fastkit_twist_capacities.png")
    wt = axis_capacities(robot, POSE, tipping=True)
    wf = axis_capacities(robot, POSE, tipping=False)
    plot_capacity_bars({"bases moving (tipping)": wt.positive,
                        "bases fixed (no tipping)": wf.positive},
                       wt.labels, ["N"] * 3 + ["N m"] * 3,
                       "FASTKIT wrench capacity at (1, 0, 0.8) m (cf. Fig. 14)",
                       HERE / "fastkit_wrench_capacities.png")
    step("deployment of the 5 m x 0.8 m box")
    dep = plan_deployment(with_stabilisers(robot), BOX, required_twist=TWIST,
                          maxiter=10, popsize=8, search=(1.5, 0.5, 0.6), grid=(6, 2, 4),
                          verify_grid=(21, 3, 9), seed=0)
    plot_deployment(dep, HERE / "fastkit_deployment.png",
                    title=f"FASTKIT deployment, 5 m x 0.1 m x 0.8 m box: worst capacity "
                          f"margin {dep.margin:.2f}")
    step("the paper's 5 m x 2 m box")
    full = plan_deployment(with_stabilisers(robot), FULL, **PLAN)
    high = raise_exits(robot, RAISE)
    out = {
        "pose": rnd(POSE),
        "limits": {"base": rnd(lim.base_max), "cable": float(lim.cable_max)},
        "twist_capacity": {"labels": list(mv.labels),
                           "active_moving": {"+": rnd(mv.positive), "-": rnd(mv.negative)},
                           "bases_fixed": {"+": rnd(fx.positive), "-": rnd(fx.negative)},
                           "navigation": {"+": rnd(nav.positive), "-": rnd(nav.negative)}},
        "wrench_capacity": {"labels": list(wt.labels),
                            "tipping": {"+": rnd(wt.positive), "-": rnd(wt.negative)},
                            "no_tipping": {"+": rnd(wf.positive), "-": rnd(wf.negative)}},
        "deployment": {"workspace": BOX, "required_twist": TWIST, "stabilisers": True,
                       "feasible": dep.success,
                       "base_poses": {k: rnd(v) for k, v in dep.base_poses.items()},
                       "margin": round(dep.margin, 4), "twist_margin": round(dep.twist_margin, 4),
                       "points": len(dep.points), "evaluations": dep.evaluations},
        "full_height_5x2m": {"workspace": FULL, "feasible": full.success,
                             "refuted_without_search": full.refuted,
                             "evaluations": full.evaluations,
                             "reason": "" if full.success else full.message,
                             "certificate": certificate(full.lift_bound)},
        "tallest": tallest(with_stabilisers(robot)),
        "exits_raised_0.5m": {"exit_heights": sorted(set(rnd(high.exits_world[:, 2]))),
                              "certificate_5x2m": certificate(lift_bound(high, FULL)),
                              "tallest": tallest(with_stabilisers(high))},
    }
    step("done")
    (HERE / "fastkit_motion.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
