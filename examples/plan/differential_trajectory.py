"""Execute the paper corridor's plan with differential-drive robots (issue 28).

Plans the corridor, turns the rigid team motion into one trajectory per robot (heading
along the motion, turns in place where it turns sharply) at 0.2 m/s, 0.5 m/s^2 and 1 rad/s,
writes it as CSV and prints its outcome. Run from the repository root:

    .venv/bin/python examples/plan/differential_trajectory.py [out.csv]
"""

from __future__ import annotations

import sys
from pathlib import Path

from taut.io import load_plan_scenario
from taut.io.robot_trajectories import save_robot_trajectories
from taut.plan import plan, robot_trajectories


def main(out: str = "out/paper_corridor_differential.csv") -> None:
    scenario = load_plan_scenario(Path(__file__).parent / "paper_corridor.yaml")
    result = plan(scenario)
    tr = robot_trajectories(result, drive="differential", max_speed=0.2, max_accel=0.5,
                            max_yaw_rate=1.0)
    print(tr.message)
    print(f"{len(tr.times)} samples; robot 1 starts at {tr.poses[0, 0]} (x m, y m, heading "
          f"rad) and ends at t = {tr.duration:.2f} s")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    save_robot_trajectories(out, tr)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
