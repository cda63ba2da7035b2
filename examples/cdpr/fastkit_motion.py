"""Regenerate the FASTKIT motion figures and numbers of this folder (issue 6):

* ``fastkit_twist_capacities.png``: largest pure platform velocity along +x, +y, +z and about
  them with the active base moving vs all bases fixed (task mode), like the paper's Fig. 13;
* ``fastkit_wrench_capacities.png``: largest extra force/moment along each axis with the
  mobile bases' tipping constraints ("bases moving", mobile) vs without (bases bolted like a
  fixed frame), like Fig. 14;
* ``fastkit_deployment.png``: top view of a planned deployment for the 5 m long workspace;
* ``fastkit_motion.json``: every number of the figures.

Run: ``python examples/cdpr/fastkit_motion.py`` (about 20 s).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from taut.cdpr import axis_capacities, with_stabilisers
from taut.cdpr.deploy import plan_deployment
from taut.cdpr.twist import fastkit_motion_limits, twist_capacities
from taut.io.cdpr_model import load_cdpr_model
from taut.viz.cdpr_motion import plot_capacity_bars, plot_deployment

HERE = Path(__file__).resolve().parent
POSE = np.array([1.0, 0.0, 0.8, 0.0, 0.0, 0.0])     # 1 m off-centre towards the passive base
BOX = [[-2.5, -0.05, 0.2], [2.5, 0.05, 1.0]]
TWIST = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]


def rnd(a) -> list:
    return [round(float(x), 4) for x in np.ravel(a)]


def main() -> None:
    robot = load_cdpr_model("fastkit")
    lim = fastkit_motion_limits()
    mv = twist_capacities(robot, POSE, lim, "task")          # active base moving
    fx = twist_capacities(robot, POSE, lim, "task", ())      # all bases fixed
    nav = twist_capacities(robot, POSE, lim, "navigation")
    plot_capacity_bars({"active base moving": mv.positive[0], "bases fixed": fx.positive[0]},
                       mv.labels, ["m/s"] * 3 + ["rad/s"] * 3,
                       "FASTKIT twist capacity at (1, 0, 0.8) m (cf. Fig. 13)",
                       HERE / "fastkit_twist_capacities.png")
    wt = axis_capacities(robot, POSE, tipping=True)
    wf = axis_capacities(robot, POSE, tipping=False)
    plot_capacity_bars({"bases moving (tipping)": wt.positive[0],
                        "bases fixed (no tipping)": wf.positive[0]},
                       wt.labels, ["N"] * 3 + ["N m"] * 3,
                       "FASTKIT wrench capacity at (1, 0, 0.8) m (cf. Fig. 14)",
                       HERE / "fastkit_wrench_capacities.png")
    dep = plan_deployment(with_stabilisers(robot, True), BOX, required_twist=TWIST,
                          maxiter=10, popsize=8, search=(1.5, 0.5, 0.6), grid=(6, 2, 4),
                          verify_grid=(21, 3, 9), seed=0)
    plot_deployment(dep, HERE / "fastkit_deployment.png",
                    title=f"FASTKIT deployment, 5 m x 0.1 m x 0.8 m box: worst capacity "
                          f"margin {dep.margin:.2f}")
    full = plan_deployment(with_stabilisers(robot, True), [[-2.5, -0.05, 0.0],
                                                           [2.5, 0.05, 2.0]],
                           maxiter=10, popsize=8, search=(1.5, 0.5, 0.6), grid=(6, 2, 4),
                           verify_grid=(11, 3, 9), seed=0)
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
                       "feasible": dep.feasible,
                       "base_poses": {k: rnd(v) for k, v in dep.base_poses.items()},
                       "margin": round(dep.margin, 4), "twist_margin": round(dep.twist_margin, 4),
                       "points": len(dep.points), "evaluations": dep.evaluations},
        "full_height_5x2m": {"workspace": [[-2.5, -0.05, 0.0], [2.5, 0.05, 2.0]],
                             "feasible": full.feasible, "margin": round(full.margin, 4),
                             "reason": full.reason,
                             "base_poses": {k: rnd(v) for k, v in full.base_poses.items()}},
    }
    (HERE / "fastkit_motion.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
