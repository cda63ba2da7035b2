"""Convergence of the MuJoCo sheet check with the mesh (the table in README.md).

Usage::

    python examples/physics/convergence.py [--meshes 7,10,13,16] [--teams 2] [--no-examples]

For the FK paper's Examples 1 and 2 and a few random teams (seed 31; N = 3-8, sheets
500-1000 mm across, hold heights 0.8-1.5 sheet radii), runs
:func:`taut.physics.replay_equilibria` at each mesh (spacings across the sheet's widest
vertex pair) and prints, per stable state, how far the tied point load and the released
ball sit from taut's object position (height and lateral, mm), the held verdict, the
run's status, and the wall time of the whole check. The ball radius scales with the
spacing (0.05 spacings), so the released ball shrinks as the mesh refines: its height
difference is the part of the error the discretisation (and ball size) contributes.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from taut.io import load_sheet_scenario
from taut.physics import replay_equilibria
from taut.physics._mesh import sheet_mesh_spacing
from taut.sheet import SheetTeam, random_hanging_team

SHEET = Path(__file__).resolve().parent.parent / "sheet"


def teams(n_random: int, examples: bool = True) -> list[tuple[str, SheetTeam, np.ndarray]]:
    out = []
    for name, file in (("Example 1", "example1.yaml"),
                       ("Example 2", "example2_r2_r4_353mm.yaml"))[:2 if examples else 0]:
        sc = load_sheet_scenario(SHEET / file)
        assert sc.formation is not None
        out.append((name, sc.team, sc.formation))
    rng = np.random.default_rng(31)
    while len(out) < (2 if examples else 0) + n_random:
        team, R = random_hanging_team(rng)
        out.append((f"random N={team.n}", team, R))
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", default="7,10,13,16")
    ap.add_argument("--teams", type=int, default=2)
    ap.add_argument("--no-examples", action="store_true", help="random teams only")
    a = ap.parse_args()
    meshes = [int(m) for m in a.meshes.split(",")]
    print("| team | mesh | spacing [mm] | check s | state | held | status | tied dz | "
          "tied lateral | released dz | released lateral |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, team, R in teams(a.teams, not a.no_examples):
        for mesh in meshes:
            t0 = time.perf_counter()
            r = replay_equilibria(team, R, mesh=mesh)
            wall = time.perf_counter() - t0
            h = sheet_mesh_spacing(team.sheet.vertices, mesh)
            for s in r.states:
                if s.kind != "stable":
                    continue
                label = "{" + ",".join(str(i + 1) for i in s.taut) + "}"
                print(f"| {name} | {mesh} | {h:.0f} | {wall:.1f} | {label} | "
                      f"{'yes' if s.held else 'NO'} | {s.status} | "
                      f"{s.tied_difference[2]:+.1f} | {np.hypot(*s.tied_difference[:2]):.1f} | "
                      f"{s.difference[2]:+.1f} | {np.hypot(*s.difference[:2]):.1f} |",
                      flush=True)


if __name__ == "__main__":
    main()
