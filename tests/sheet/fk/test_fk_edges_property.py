"""The issue-25 invariants on many near-degenerate teams (slow suite): regular and random
sheets, scaled / rotated / shifted copies, noise 1e-13..1e-4, coordinates written to finite
digits, collinear and coincident robots, and generic random teams. For every feasible
formation: no state reported twice, and every method (the exhaustive one where N <= 12)
and the batch agree on the stable positions; for the (noisy, rounded) copies of regular
sheets at least one stable state.

The number of teams is ``TAUT_EDGE_TEAMS``: 2,000 by default (a few minutes, what CI
runs), ``TAUT_EDGE_TEAMS=100000`` for the issue's count (hours on one core); each team
is drawn from its own seed, so a failure names its seed.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

import taut.sheet as ts
from taut.errors import InfeasibleFormationError
from taut.sheet import FKSolver, Sheet, SheetTeam
from taut.sheet._tol import MERGE_RTOL

TEAMS = int(os.environ.get("TAUT_EDGE_TEAMS", "2000"))
#: Teams a test case checks (the cases run in parallel under pytest-xdist).
CHUNK = 500
NOISES = [0.0, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4]


def draw_team(seed: int) -> tuple[Sheet, np.ndarray, str]:
    """One team of the issue's families, and a label saying which."""
    rng = np.random.default_rng(seed)
    family = rng.choice(["regular", "random", "generic", "collinear", "coincident"],
                        p=[0.4, 0.3, 0.1, 0.1, 0.1])
    n = int(rng.integers(3, 17))
    if family == "generic":
        sheet, R = ts.random_team(n, rng)
        return sheet, R, f"generic n={n}"
    if family == "regular":
        a = 2 * np.pi * np.arange(n) / n
        V = np.c_[np.cos(a), np.sin(a)] * rng.uniform(0.2, 5.0)
    else:
        V = ts.random_team(n, rng)[0].vertices
    scale = rng.uniform(0.5, 0.99)
    th = rng.uniform(0, 2 * np.pi)
    Q = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    size = float(np.ptp(V, axis=0).max())
    R = scale * (V - V.mean(axis=0)) @ Q.T + rng.uniform(-3, 3, 2) * size
    if family == "collinear":                    # every robot on one line through the centre
        d = np.array([np.cos(th), np.sin(th)])
        R = R.mean(axis=0) + np.outer((R - R.mean(axis=0)) @ d, d)
    elif family == "coincident":                 # two robots at one point
        i = int(rng.integers(n))
        R[(i + 1) % n] = R[i]
    noise = float(rng.choice(NOISES))
    R = R + noise * size * rng.standard_normal(R.shape)
    digits = int(rng.choice([0, 4, 6, 9]))
    label = f"{family} n={n} scale={scale:.3f} noise={noise:g} digits={digits}"
    if digits:
        V, R = np.round(V, digits), np.round(R, digits)
    return Sheet(V), R, label


def check_team(seed: int) -> str | None:
    """The invariants on team ``seed``; None when they hold (or the team is out of the
    model: infeasible formation, or the object would hang below the floor), else why."""
    try:
        sheet, R, label = draw_team(seed)
        team = SheetTeam(sheet, 4.0 * sheet.size)
        results = {m: FKSolver(team, method=m).solve(R) for m in ("fast", "subsets")}
        results["fast-numpy"] = FKSolver(team, backend="numpy").solve(R)
        if sheet.n <= 12:
            results["exhaustive"] = ts.forward_kinematics(team, R, method="exhaustive")
        results["batch"] = ts.forward_kinematics_batch(team, R[None]).result(0)
    except InfeasibleFormationError:
        return None
    except Exception as exc:                     # a crash is a failure too
        return f"seed {seed}: {type(exc).__name__}: {exc}"
    tol = MERGE_RTOL * sheet.size
    # A copy of a regular sheet (up to the noise and digits) always holds the object: at
    # the centre, on every cable (FK paper Lemma 2: equal cable lengths, the circumcentre).
    # Elsewhere the object may slide to the sheet's free edge (e.g. a copy of an obtuse
    # triangle: its circumcentre lies outside; a 2-cable state, outside the model): no
    # stable state is then the right answer, and the methods must agree on it.
    must_hold = label.startswith("regular") and "collinear" not in label
    ref = None
    for name, res in results.items():
        if must_hold and not res.success:
            return f"seed {seed} ({label}): {name} has no stable state: {res.message}"
        eqs = res.equilibria
        for i, a in enumerate(eqs):
            for b in eqs[i + 1:]:
                if max(np.abs(a.object - b.object).max(),
                       np.abs(a.contact - b.contact).max()) <= tol:
                    return f"seed {seed} ({label}): {name} reports {a} twice"
        pts = np.array(sorted(e.object.tolist() for e in res.stable))
        if ref is None:
            ref = pts
        elif len(pts) != len(ref) or (len(pts) and np.abs(pts - ref).max() > 2 * tol):
            return (f"seed {seed} ({label}): {name} stable {pts.tolist()} vs fast "
                    f"{ref.tolist()}")
    return None


@pytest.mark.slow
@pytest.mark.parametrize("start", range(0, TEAMS, CHUNK))
def test_edge_teams_have_one_answer(start):
    failures = [f for f in (check_team(s) for s in range(start, min(start + CHUNK, TEAMS)))
                if f is not None]
    assert not failures, f"{len(failures)} failure(s); first: " + "; ".join(failures[:5])


@pytest.mark.xfail(strict=True, reason="open: the one failure in seeds 0-99,999 (a regular "
                   "hexagon held at 0.55x, noise 1e-9, 6 digits): fast finds no stable state "
                   "and the direct minimisation a non-strict lowest one")
def test_the_known_open_case_seed_34152():
    assert check_team(34152) is None
