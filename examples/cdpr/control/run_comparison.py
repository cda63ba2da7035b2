"""FASTKIT paper §2.2, measured: velocity control vs torque control on the same pick-and-place
at 1 m/s with the same seeded 5 mm exit-point errors. The deployment drive (task mode, eq. 8:
the active base on its wheels while the platform holds) is ``examples/cdpr/fastkit_base_drive.py``.

Run from the repository root:  python examples/cdpr/control/run_comparison.py
Writes results.json and the figures next to this script.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from taut.cdpr import (ModelErrors, TorqueController, VelocityController, pick_and_place,
                       simulate, with_stabilisers)
from taut.io.cdpr_model import load_cdpr_model
from taut.viz.cdpr_sim import animate_control, plot_comparison, plot_control

HERE = Path(__file__).resolve().parent
WAYPOINTS = [[-1.5, 0.0, 0.6], [-1.5, 0.0, 1.1], [1.5, 0.0, 1.1], [1.5, 0.0, 0.6]]
SEEDS = range(5)


def summary(run):
    return {"status": run.status, "max_tracking_error_mm": 1e3 * float(run.tracking_error.max()),
            "rms_tracking_error_mm": 1e3 * float(np.sqrt(np.mean(run.tracking_error ** 2))),
            "min_tension_N": float(run.tensions.min()), "max_tension_N": float(run.tensions.max()),
            "slack_time_s": run.slack_time,
            "worst_over_tension_N": max(run.worst_over_tension, 0.0),
            "min_tipping_margin_Nm": float(run.tipping_margin.min()),
            "events": len(run.events)}


def main() -> None:
    robot = with_stabilisers(load_cdpr_model("fastkit"))     # task mode: stabilisers down
    ref = pick_and_place(robot, WAYPOINTS, speed=1.0, dwell=0.5)
    out = {"waypoints_m": WAYPOINTS, "speed_m_s": 1.0, "exit_error_std_m": 0.005,
           "duration_s": ref.duration, "runs": []}
    first = {}
    for seed in SEEDS:
        errs = ModelErrors(exit_offset=0.005, seed=seed)
        for ctl in (VelocityController(), TorqueController()):
            run = simulate(robot, ref, ctl, model_errors=errs)
            out["runs"].append({"seed": seed, "controller": ctl.name, **summary(run)})
            if seed == 0:
                first[ctl.name] = run
            print(seed, ctl.name, run.message)
    plot_comparison({"velocity control": first["velocity"], "torque control": first["torque"]},
                    HERE / "comparison.png",
                    "FASTKIT pick-and-place at 1 m/s, exit errors 5 mm (seed 0)")
    for name, run in first.items():
        plot_control(run, HERE / f"{name}_control.png")
    animate_control(robot, first["torque"], HERE / "torque_control.gif", frames=40, fps=8)
    (HERE / "results.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    from taut.cli._progress import working  # progress on stderr past 2 s
    with working("run_comparison"):
        main()
