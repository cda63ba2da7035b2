"""Is the 4 ms step small enough? The sheet checks at half the step (the table in README.md).

Usage::

    python examples/physics/timestep.py [--steps 0.004,0.002] [--teams 3]

Runs :func:`taut.physics.replay_equilibria` on the FK paper's Example 1 and the first
random teams of issue 31's sample (seed 2026) with the model's time step replaced, and
prints per state the tied and released height differences from taut's (mm), the sheet's
sideways pull, the status and the wall time of the check. The soft constraints' time
constant stays 8 ms (two steps at 4 ms, MuJoCo's recommended floor, four at 2 ms) and the
node mass scales with the step squared (``NODE_MASS_PER_DT2``), so only the integration
error changes. A run that MuJoCo flags (bad position, velocity or acceleration; a full
constraint buffer) is reported ``diverged`` by the check itself.
"""

from __future__ import annotations

import argparse
import time
from functools import partial
from pathlib import Path

import numpy as np

from taut.io import load_sheet_scenario
from taut.physics import replay_equilibria
from taut.physics import sheet as sheet_check
from taut.sheet import random_hanging_team

SHEET = Path(__file__).resolve().parent.parent / "sheet"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", default="0.004,0.002")
    ap.add_argument("--teams", type=int, default=3)
    a = ap.parse_args()
    sc = load_sheet_scenario(SHEET / "example1.yaml")
    assert sc.formation is not None
    runs = [("Example 1", sc.team, sc.formation)]
    rng = np.random.default_rng(2026)
    runs += [(f"sample team {k}", *random_hanging_team(rng)) for k in range(a.teams)]
    build = sheet_check.build_sheet_sim
    print("| team | step [ms] | check s | state | held | pull/mg | status | tied dz | "
          "released dz |")
    print("|---|---|---|---|---|---|---|---|---|")
    try:
        for name, team, R in runs:
            for dt in (float(s) for s in a.steps.split(",")):
                sheet_check.build_sheet_sim = partial(build, timestep=dt)
                t0 = time.perf_counter()
                r = replay_equilibria(team, R)
                wall = time.perf_counter() - t0
                for s in r.states:
                    label = "{" + ",".join(str(i + 1) for i in s.taut) + "}"
                    print(f"| {name} | {dt * 1e3:g} | {wall:.1f} | {label} | "
                          f"{'yes' if s.held else 'no'} | {s.sliding:.3f} | {s.status} | "
                          f"{s.tied_difference[2]:+.2f} | {s.difference[2]:+.2f} |")
    finally:
        sheet_check.build_sheet_sim = build


if __name__ == "__main__":
    main()
