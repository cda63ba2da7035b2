"""Does MuJoCo's own force reading of the held verdict's pull converge to the check's rigid
reading as the soft constraints are made stiffer? (README.md, "Hold resolution").

Usage::

    python examples/physics/stiffness.py [--steps 0.004,0.002,0.001,0.0005]
                                         [--dmin 0.99,0.9999] [--mass fixed|per-dt2]
                                         [--mesh 10] [--seed 2026] [--extra 1]
                                         [--states 10:2,5,6 13:1,5,7,8 ...]

Draws issue 31's random sample with ``--seed`` as ``hold_resolution.py`` does and runs,
for each ``team:state``, only the *tied* half of the check (``_tied_run``) at each
combination of time step (s) and SOLIMP ``dmin`` (dimensionless; ``dmax`` stays MuJoCo's
ceiling 0.9999, so ``dmin`` 0.9999 makes the impedance constant). The soft constraints'
time constant follows the step (``SOLREF`` = 2 steps, as the default); the settle budget
and rest speed stay in seconds and m/s (``MAX_SETTLE_TIME``, ``TIED_SETTLE_SPEED``).

At rest a soft limit stretches by about (1 - d) / d^2 * (tc * dmax)^2 * f / m (MuJoCo's
reference acceleration -k d r balanced by the compliance R f = (1 - d) / d * f / m; d the
impedance, tc the time constant, f the tendon force, m the node mass). ``--mass
per-dt2`` keeps ``NODE_MASS_PER_DT2`` (the default model's rule: node mass scales with
the step squared), which keeps tc^2 / m and with it the stretch the same at every step;
``--mass fixed`` keeps the node mass of the 4 ms default (3 g per kg of ball), so the
stretch falls like the step squared. The node masses are gravity-compensated, so
neither changes the statics.

Prints one Markdown row per state and setting: taut's pull (fraction of the weight,
``model_pull``); the check's rigid reading (``_taut_cable_pull``) and MuJoCo's force
reading (``_force_pull``) where the check reads them (the ball slower than
``TIED_SETTLE_SPEED``), then both again after ``--extra`` more simulated seconds, with
their difference and the largest stretch of the contact node's corner tendons at their
limit there (mm, scenario units: the sheet's own unit); the tied run's outcome and its
wall time as the check does it (mesh, build, ramp, settle; s) and with the extra
seconds. The module constants are patched for the run only.
"""

from __future__ import annotations

import argparse
import time
from functools import partial

import mujoco
import numpy as np

from hold_resolution import label, picked
from taut._units import GRAVITY
from taut.physics import _run, _tol
from taut.physics import sheet as sheet_check
from taut.physics._mesh import sheet_mesh, sheet_mesh_spacing
from taut.physics._sheet_model import SheetSim
from taut.physics._statics import model_pull
from taut.sheet import SheetTeam, forward_kinematics

DEFAULT_STATES = "10:2,5,6 13:1,5,7,8 9:1,4,5,6 14:2,3,6 17:3,4,6,7"


def corner_stretch(sim: SheetSim) -> float:
    """Largest stretch beyond its length of a corner tendon at its limit that ends at the
    contact node, scenario units (0 when none is at its limit)."""
    _, other, ids = _run._contact_tendons(sim)
    ids = ids[np.isin(other, sim.mesh.corners)]
    if len(ids) == 0:
        return 0.0
    over = np.asarray(sim.data.ten_length)[ids] - np.asarray(sim.model.tendon_range)[ids, 1]
    return float(over.max()) / sim.scale


def pulls(sim: SheetSim) -> tuple[np.ndarray | None, np.ndarray]:
    """The rigid reading (None where the check falls back) and the force reading, N."""
    return _run._taut_cable_pull(sim), _run._force_pull(sim)


def fmt(pull: np.ndarray | None, weight: float) -> str:
    return "-" if pull is None else f"{np.linalg.norm(pull) / weight:.2e}"


def row(team: SheetTeam, R: np.ndarray, name: str, want: tuple[int, ...], mesh: int,
        dt: float, dmin: float, extra: float) -> str:
    eq = next((e for e in forward_kinematics(team, R).equilibria if tuple(e.taut) == want),
              None)
    if eq is None:
        raise SystemExit(f"{label(want)} is not a rest state of team {name}")
    sheet, z = team.sheet, team.hold_height
    mass = _tol.BALL_MASS if team.mass is None else float(team.mass)
    weight = mass * GRAVITY
    model = model_pull(sheet.vertices, R, z, want, np.asarray(eq.object, dtype=float),
                       np.asarray(eq.contact))
    t0 = time.perf_counter()
    m = sheet_mesh(sheet.vertices, mesh, contact=eq.contact)
    radius = _tol.BALL_RADIUS * sheet_mesh_spacing(sheet.vertices, mesh)
    sim, outcome = sheet_check._tied_run(sheet, R, z, m, radius, corner_tendons=True,
                                         mass=mass)
    wall = time.perf_counter() - t0
    rigid0, force0 = pulls(sim)
    for _ in range(int(round(extra / sim.model.opt.timestep))):
        mujoco.mj_step(sim.model, sim.data)
    rigid, force = pulls(sim)
    total = time.perf_counter() - t0
    diff = None if rigid is None else force - rigid
    return (f"| {name} | {label(want)} | {eq.kind} | {model:.2e} | {dt * 1e3:g} | {dmin:g} "
            f"| {fmt(rigid0, weight)} | {fmt(force0, weight)} | {fmt(rigid, weight)} "
            f"| {fmt(force, weight)} | {fmt(diff, weight)} | {corner_stretch(sim):.2g} "
            f"| {outcome} | {wall:.1f} | {total:.1f} |")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", default="0.004,0.002,0.001,0.0005", help="time steps, s")
    ap.add_argument("--dmin", default="0.99,0.9999", help="SOLIMP dmin values")
    ap.add_argument("--mass", choices=("fixed", "per-dt2"), default="fixed",
                    help="node mass: that of the 4 ms default, or NODE_MASS_PER_DT2 * dt^2")
    ap.add_argument("--mesh", type=int, default=10)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--states", nargs="+", default=DEFAULT_STATES.split(),
                    help="team:cables, 0-based team index, 1-based robot numbers")
    ap.add_argument("--extra", type=float, default=1.0,
                    help="simulated seconds after the check's reading, s")
    a = ap.parse_args()
    picks, teams = picked(a.states, a.seed)
    saved = (sheet_check.build_sheet_sim, _tol.SOLREF, _tol.SOLIMP, _tol.NODE_MASS_PER_DT2)
    build, solref, solimp, per_dt2 = saved
    later = f"+{a.extra:g} s"
    print("| team | state | taut says | taut's pull / mg | step [ms] | dmin "
          "| rigid pull / mg (check) | force pull / mg | "
          f"rigid ({later}) | force ({later}) | |force - rigid| ({later}) "
          f"| corner stretch [mm] ({later}) | tied run | wall s | wall s ({later}) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    try:
        for t, want in picks:
            team, R = teams[t]
            for dmin in (float(s) for s in a.dmin.split(",")):
                for dt in (float(s) for s in a.steps.split(",")):
                    sheet_check.build_sheet_sim = partial(build, timestep=dt)
                    _tol.SOLREF = (2 * dt, solref[1])
                    _tol.SOLIMP = (dmin, *solimp[1:])
                    _tol.NODE_MASS_PER_DT2 = (per_dt2 * (_tol.TIMESTEP / dt) ** 2
                                              if a.mass == "fixed" else per_dt2)
                    print(row(team, R, str(t), want, a.mesh, dt, dmin, a.extra), flush=True)
    finally:
        (sheet_check.build_sheet_sim, _tol.SOLREF, _tol.SOLIMP,
         _tol.NODE_MASS_PER_DT2) = saved


if __name__ == "__main__":
    main()
