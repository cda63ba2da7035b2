"""Release one rest state of one team at a given mesh (the marginal state of README.md).

Usage::

    python examples/physics/marginal_state.py [--meshes 10,16] [--seed 2026] [--team 3]
                                              [--state 1,4,5] [--log]

Draws team ``--team`` (0-based) of the random sample with ``--seed`` exactly as
``bench/bench_physics.py`` and ``tests/physics/test_sheet_check.py`` do
(:func:`taut.sheet.random_hanging_team`, one generator, teams drawn in order), finds the
rest state with taut cables ``--state`` (1-based robot numbers) in
:func:`taut.sheet.forward_kinematics`, and runs only the *released* half of
:func:`taut.physics.replay_equilibria` for it at each mesh: the same function that check
calls per state (``_release_over``: the ball, radius 0.05 spacings, held over taut's
object position while it presses the sheet down from the flat start, then let go and
settled for up to 6 s simulated). The tied run, the other states and the held verdict are
skipped: at a fine mesh each state costs minutes.

Prints one Markdown row per mesh: spacing (mm), nodes, ball radius (mm), how the hold with
the contact node pinned under the ball ended (``settled``; ``diverged`` or ``left``: the
sheet was then formed again unpinned, as the check does) and its wall time (s), the
release's outcome (``settled``, ``moving``, ``left``, ``diverged``), simulated seconds after
release, released dx, dy, dz from taut's object position (mm), the taut state the ball came
to rest nearest (its set and height difference, mm), and the wall time of the whole
release (s). The default is issue
31's exception: team 3 of the seed-2026 sample (N = 5), stable {1,4,5} at z 537 mm, whose
basin towards {1,2,4} is about 1.5 mm deep and 31 mm wide. ``--log`` prints every settle
phase's progress on stderr (ball centre, active constraints ``nefc``, Newton iterations of
the last step, wall time): where a slow run spends its time.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import numpy as np

from taut.physics import _run, _tol
from taut.physics._mesh import sheet_mesh, sheet_mesh_spacing
from taut.physics.sheet import _release_over
from taut.sheet import Equilibrium, SheetTeam, forward_kinematics, random_hanging_team


def sample_team(seed: int, k: int) -> tuple[SheetTeam, np.ndarray]:
    """Team ``k`` (0-based) of the random sample drawn with ``seed``."""
    rng = np.random.default_rng(seed)
    for _ in range(k + 1):
        team, R = random_hanging_team(rng)
    return team, R


class _Progress(list):
    """A settle phase's trace that prints, at every check (0.1 s simulated), the ball's
    centre (simulation metres), the active constraints and solver iterations of the last
    step, and the wall time: where a slow run spends its time."""

    def __init__(self, sim: Any, phase: int) -> None:
        super().__init__()
        self.sim, self.phase, self.t0 = sim, phase, time.perf_counter()

    def append(self, row: Any) -> None:
        d = self.sim.data
        print(f"  phase {self.phase} t {row[0]:6.2f} s  ball {row[1]:+.4f} {row[2]:+.4f} "
              f"{row[3]:+.4f} m  nefc {d.nefc:6d}  iters {int(d.solver_niter[0]):3d}  "
              f"wall {time.perf_counter() - self.t0:7.1f} s", file=sys.stderr, flush=True)


def watch_phases(verbose: bool) -> list[tuple[str, float, float]]:
    """Record every settle phase's (outcome, simulated s, wall s) in the returned list,
    and with ``verbose`` print its progress on stderr (``--log``). The first phase of a
    release is the hold with the contact node pinned under the ball; when it ends
    ``left`` or ``diverged``, ``_release_over`` forms the sheet again unpinned."""
    plain = _run.settle_phase
    phases: list[tuple[str, float, float]] = []

    def recorded(sim: Any, max_time: float, trace: Any = None, *args: Any, **kw: Any
                 ) -> tuple[str, float]:
        t0 = time.perf_counter()
        log = _Progress(sim, len(phases) + 1) if verbose else trace
        out = plain(sim, max_time, log, *args, **kw)
        phases.append((out[0], out[1], time.perf_counter() - t0))
        if verbose:
            print(f"  phase {len(phases)}: {out[0]} after {out[1]:.1f} s simulated",
                  file=sys.stderr, flush=True)
        return out

    _run.settle_phase = recorded
    return phases


def label(taut: tuple[int, ...]) -> str:
    return "{" + ",".join(str(i + 1) for i in taut) + "}"


def release_row(team: SheetTeam, R: np.ndarray, eqs: list[Equilibrium], eq: Equilibrium,
                mesh: int, phases: list[tuple[str, float, float]]) -> str:
    """Release ``eq``'s object at ``mesh`` and format the outcome as a Markdown row."""
    sheet = team.sheet
    h = sheet_mesh_spacing(sheet.vertices, mesh)
    radius = _tol.BALL_RADIUS * h
    m = sheet_mesh(sheet.vertices, mesh, contact=eq.contact)
    pred = np.asarray(eq.object, dtype=float)
    mass = _tol.BALL_MASS if team.mass is None else team.mass
    phases.clear()
    t0 = time.perf_counter()
    outcome, t_rel, found = _release_over(sheet, R, team.hold_height, m, pred[:2], radius,
                                          corner_tendons=True, mass=mass)
    wall = time.perf_counter() - t0
    pin = phases[0]
    head = (f"| {mesh} | {h:.1f} | {len(m.nodes)} | {radius:.2f} | {pin[0]} ({pin[2]:.0f} s "
            f"wall) | {outcome} | {t_rel:.1f} |")
    if found is None:
        return f"{head} - | - | {wall:.1f} |"
    settled = found[0]
    d = settled - pred
    near = min(eqs, key=lambda e: float(np.linalg.norm(settled - np.asarray(e.object))))
    dz_near = settled[2] - float(near.object[2])
    return (f"{head} {d[0]:+.1f}, {d[1]:+.1f}, **{d[2]:+.1f}** | "
            f"{label(tuple(near.taut))} ({dz_near:+.1f}) | {wall:.1f} |")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", default="10,16", help="comma-separated meshes (spacings "
                    "across the sheet's widest vertex pair)")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--team", type=int, default=3, help="0-based index in the sample")
    ap.add_argument("--state", default="1,4,5", help="taut cables, 1-based robot numbers")
    ap.add_argument("--log", action="store_true", help="print each settle phase's "
                    "progress on stderr (ball, active constraints, solver iterations)")
    a = ap.parse_args()
    phases = watch_phases(a.log)
    team, R = sample_team(a.seed, a.team)
    eqs = list(forward_kinematics(team, R).equilibria)
    want = tuple(sorted(int(i) - 1 for i in a.state.split(",")))
    eq = next((e for e in eqs if tuple(e.taut) == want), None)
    if eq is None:
        raise SystemExit(f"state: {label(want)} is not a rest state of team {a.team} "
                         f"(taut: {', '.join(label(tuple(e.taut)) for e in eqs)})")
    print(f"team {a.team} of seed {a.seed}: N = {team.n}, {label(want)} {eq.kind}, "
          f"taut's object at z {eq.object[2]:.1f}; other states: "
          + ", ".join(f"{label(tuple(e.taut))} z {e.object[2]:.1f}" for e in eqs if e is not eq))
    print("\n| mesh | spacing [mm] | nodes | ball r [mm] | pinned hold | outcome | "
          "s after release | released dx, dy, dz [mm] | nearest taut state (dz) | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for mesh in (int(s) for s in a.meshes.split(",")):
        print(release_row(team, R, eqs, eq, mesh, phases), flush=True)


if __name__ == "__main__":
    main()
