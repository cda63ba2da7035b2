"""How the held verdict's pull changes with the mesh, read two ways (README.md, "Hold
resolution").

Usage::

    python examples/physics/hold_resolution.py [--meshes 10,14,20] [--seed 2026]
                                               [--states 9:1,4,5,6 10:2,5,6 ...] [--extra 2]

Draws the random sample with ``--seed`` exactly as ``bench/bench_physics.py`` does
(:func:`taut.sheet.random_hanging_team`, one generator, teams drawn in order) and, for
each ``team:state`` (0-based team index, taut cables as 1-based robot numbers), runs only
the *tied* half of :func:`taut.physics.replay_equilibria` at each mesh: the same function
that check calls per state (``_tied_run``: the object tied to the contact node as a point
load, settled until the ball moves slower than ``TIED_SETTLE_SPEED``). The release is
skipped.

Prints one Markdown row per state and mesh: taut's verdict and its own pull (fraction of
the weight, ``model_pull``), spacing (mm), the tied run's outcome, ``sliding`` as the
check reads it (the corner tendons the simulation has taut, read as rigid cables), the
pull of MuJoCo's own tendon forces (``_force_pull``: the check's reading before issue
31 was resolved, still its reading without corner tendons), the latter again after
``--extra`` more simulated seconds (where the tied sheet is at rest: the difference is
residual motion at the check's settle threshold), and the wall time of the tied run as
the check does it (mesh, build, ramp, settle; s). The default states are the 10
non-equilibria that the force reading could not resolve (model pull below its 0.05
tolerance) and the 8 stable states with the largest force pull at mesh 10 in the
30-team sample (seed 2026).
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from taut._units import GRAVITY
from taut.physics import _run, _tol
from taut.physics._mesh import sheet_mesh, sheet_mesh_spacing
from taut.physics._statics import model_pull
from taut.physics.sheet import _sliding, _tied_run
from taut.sheet import SheetTeam, forward_kinematics, random_hanging_team

DEFAULT_STATES = ("9:1,4,5,6 13:1,5,7,8 17:3,4,6,7 21:1,2,5,6 22:1,2,5,6 22:2,3,4,5 "
                  "28:1,4,5,6 28:1,4,6,7 28:1,4,5,6,7 8:1,2,3,4 "
                  "10:2,5,6 14:2,3,6 17:2,3,7,8 4:2,4,5 11:1,4,5 26:3,7,8 17:3,6,7 21:2,4,5")


def sample(seed: int, teams: int) -> list[tuple[SheetTeam, np.ndarray]]:
    """The first ``teams`` teams of the random sample drawn with ``seed``."""
    rng = np.random.default_rng(seed)
    return [random_hanging_team(rng) for _ in range(teams)]


def label(taut: tuple[int, ...]) -> str:
    return "{" + ",".join(str(i + 1) for i in taut) + "}"


def row(team: SheetTeam, R: np.ndarray, name: str, want: tuple[int, ...], mesh: int,
        extra: float) -> str:
    eq = next((e for e in forward_kinematics(team, R).equilibria if tuple(e.taut) == want),
              None)
    if eq is None:
        raise SystemExit(f"{label(want)} is not a rest state of team {name}")
    sheet, z = team.sheet, team.hold_height
    mass = _tol.BALL_MASS if team.mass is None else float(team.mass)
    model = model_pull(sheet.vertices, R, z, want, np.asarray(eq.object, dtype=float),
                       np.asarray(eq.contact))
    t0 = time.perf_counter()
    m = sheet_mesh(sheet.vertices, mesh, contact=eq.contact)
    radius = _tol.BALL_RADIUS * sheet_mesh_spacing(sheet.vertices, mesh)
    sim, outcome = _tied_run(sheet, R, z, m, radius, corner_tendons=True, mass=mass)
    read = _sliding(sim, mass)
    wall = time.perf_counter() - t0
    force = float(np.linalg.norm(_run._force_pull(sim))) / (mass * GRAVITY)
    for _ in range(int(round(extra / sim.model.opt.timestep))):
        mujoco.mj_step(sim.model, sim.data)
    later = float(np.linalg.norm(_run._force_pull(sim))) / (mass * GRAVITY)
    return (f"| {name} | {label(want)} | {eq.kind} | {model:.2e} | {mesh} | {m.spacing:.0f} "
            f"| {outcome} | {read:.2e} | {force:.3f} | {later:.3f} | {wall:.1f} |")


def picked(states: list[str], seed: int) -> tuple[list[tuple[int, tuple[int, ...]]], list]:
    """``team:cables`` arguments as (0-based team, 0-based taut set) and the teams of the
    sample up to the last one named."""
    picks = [(int(t), tuple(sorted(int(i) - 1 for i in c.split(","))))
             for t, c in (s.split(":") for s in states)]
    return picks, sample(seed, max(t for t, _ in picks) + 1)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", default="10,14,20")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--states", nargs="+", default=DEFAULT_STATES.split(),
                    help="team:cables, 0-based team index, 1-based robot numbers")
    ap.add_argument("--extra", type=float, default=2.0,
                    help="simulated seconds after the check's reading, s")
    a = ap.parse_args()
    picks, teams = picked(a.states, a.seed)
    print("| team | state | taut says | taut's pull / mg | mesh | spacing [mm] | tied run "
          f"| pull / mg (check) | force pull / mg | force pull (+{a.extra:g} s) | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for t, want in picks:
        team, R = teams[t]
        for mesh in (int(s) for s in a.meshes.split(",")):
            print(row(team, R, str(t), want, mesh, a.extra), flush=True)


if __name__ == "__main__":
    main()
