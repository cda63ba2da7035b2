"""A physical deployment drive on FASTKIT (issue 26, FASTKIT §2 task mode, eq. 8): the active
base drives 0.5 m towards the platform in 5 s (quintic, 0.19 m/s peak, inside the 0.2 m/s
limit of eq. 11) on its wheels, stabilisers retracted, while the cables hold the platform;
the tension distribution keeps every base upright (tipping imposed); the stabilisers deploy
once in place.

1. ``plan_base_drive`` at four platform heights: where a distribution keeps the base on its
   wheels upright, and where none does (the plan says so, naming time and poses).
2. What the previous demo did at (0.3, 0, 1.0): the closed-form tensions with the active
   base on its wheels, their worst edge margin (they ignore tipping).
3. The feasible drive simulated with every built-in law (no model error, encoder sensing):
   tracking, tensions and every monitored tipping margin (asserted >= 0 by
   ``tests/cdpr/deployment/test_base_drive.py`` for the velocity law).

Writes ``fastkit_base_drive.json`` and ``fastkit_base_drive.png`` (velocity law).
Run: ``python examples/cdpr/fastkit_base_drive.py`` (about a minute).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from taut.cdpr import (BaseMotion, ComputedTorqueController, TorqueController,
                       VelocityController, distribute_tensions, plan_base_drive,
                       reference_from_samples, simulate, tipping_moments, with_stabilisers)
from taut.io.cdpr_model import load_cdpr_model
from taut.viz.cdpr_sim import plot_control

HERE = Path(__file__).resolve().parent
HEIGHTS_M = (1.0, 0.9, 0.8, 0.7)        # platform z held at x = 0.3 m
HELD_Z_M = 0.7                          # the drive simulated
DRIVE = dict(displacement=(0.5, 0.0, 0.0), duration=5.0, start=0.2)
HOLD_S = 5.5


def _pose(z: float) -> np.ndarray:
    return np.array([0.3, 0.0, z, 0.0, 0.0, 0.0])


def plans(robot, bm) -> list[dict]:
    out = []
    for z in HEIGHTS_M:
        plan = plan_base_drive(robot, _pose(z), bm)
        print(f"z = {z} m:", plan.message)
        out.append({"platform_z_m": z, "success": plan.success, "status": plan.status,
                    "failed_at_s": None if np.isnan(plan.failed_at_s) else plan.failed_at_s,
                    "min_tipping_margin_Nm": None if np.isnan(plan.min_tipping_margin_Nm)
                    else round(plan.min_tipping_margin_Nm, 3) + 0.0,    # no -0.0
                    "message": plan.message})
    return out


def closed_form_on_wheels(robot, bm) -> dict:
    """The previous demo's reference tensions (closed form, tipping ignored) at (0.3, 0,
    1.0) with the active base on its wheels at its start pose."""
    wheels = plan_base_drive(robot, _pose(1.0), bm).drive_robot
    res = distribute_tensions(wheels, _pose(1.0), "closed_form", tipping=False)
    margins = -tipping_moments(wheels, _pose(1.0), res.tensions).moments
    return {"tensions_N": np.round(res.tensions, 2).tolist(),
            "min_tipping_margin_Nm": round(float(margins.min()), 2)}


def summary(run) -> dict:
    return {"status": run.status, "success": bool(run.success),
            "max_tracking_error_mm": round(1e3 * float(run.tracking_error.max()), 4),
            "min_tension_N": round(float(run.tensions.min()), 2),
            "max_tension_N": round(float(run.tensions.max()), 2),
            "min_tipping_margin_Nm": round(float(run.tipping_margin.min()), 3),
            "base_displacement_m": round(float(run.base_poses[-1, 0, 0]
                                               - run.base_poses[0, 0, 0]), 4)}


def main() -> None:
    robot = with_stabilisers(load_cdpr_model("fastkit"))     # parked: stabilisers down
    bm = BaseMotion.line(robot, "active", **DRIVE)
    out: dict = {"drive": {"base": "active", "displacement_m_rad": list(DRIVE["displacement"]),
                           "duration_s": DRIVE["duration"], "start_s": DRIVE["start"]},
                 "plans": plans(robot, bm),
                 "closed_form_at_z_1_m_on_wheels": closed_form_on_wheels(robot, bm)}
    plan = plan_base_drive(robot, _pose(HELD_Z_M), bm)
    t = np.linspace(0.0, HOLD_S, 12)
    ref = reference_from_samples(robot, t, np.tile(_pose(HELD_Z_M), (12, 1)))
    out["simulated"] = {"platform_pose_m_rad": _pose(HELD_Z_M).tolist(),
                        "planned_min_tipping_margin_Nm": round(plan.min_tipping_margin_Nm, 3)}
    for ctl in (VelocityController(), TorqueController(), ComputedTorqueController()):
        run = simulate(plan.drive_robot, ref, ctl, base_motion=bm)
        out["simulated"][ctl.name] = summary(run)
        print(ctl.name, run.message)
        if ctl.name == "velocity":
            plot_control(run, HERE / "fastkit_base_drive.png",
                         f"active base +0.5 m on its wheels, platform held at "
                         f"(0.3, 0, {HELD_Z_M}) m")
    (HERE / "fastkit_base_drive.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
