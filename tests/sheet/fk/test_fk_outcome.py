"""Forward kinematics follows taut's outcome convention (``success``, ``status``,
``message``): one formation, and a batch with per-formation flags."""

from __future__ import annotations

import numpy as np
import pytest

from taut._jit import HAVE_NUMBA
from taut._outcome import STATUSES
from taut.sheet import (FKSolver, Sheet, SheetTeam, forward_kinematics,
                        forward_kinematics_batch)

SQUARE = Sheet([[0, 0], [1, 0], [1, 1], [0, 1]])
INNER = 0.9 * SQUARE.vertices                 # the object hangs 0.3082 below the robots
BACKENDS = ["numba", "numpy"] if HAVE_NUMBA else ["numpy"]


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_stable_state_is_success(backend):
    res = FKSolver(SheetTeam(SQUARE, 1.0), backend=backend).solve(INNER)
    assert (res.success, res.status) == (True, "ok")
    assert res.message == "1 solution(s), 1 stable"


@pytest.mark.parametrize("method", ["fast", "subsets", "exhaustive"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_no_equilibrium_says_why(backend, method):
    """Held 0.2 high, the only state would hang 0.1082 below the floor: the library (not
    the CLI) says so, the same for every method and backend."""
    if method == "exhaustive":
        res = forward_kinematics(SheetTeam(SQUARE, 0.2), INNER, method="exhaustive")
    else:
        res = FKSolver(SheetTeam(SQUARE, 0.2), method=method, backend=backend).solve(INNER)
    assert res.equilibria == ()
    assert (res.success, res.status) == (False, "infeasible") and res.status in STATUSES
    assert res.message.startswith("no equilibrium: 1 state(s) discarded because the object "
                                  "would hang at or below the floor")
    assert "{1,2,3,4} at z_o = -0.1082" in res.message


def test_no_stable_state_is_not_success():
    """States, but none stable (here one saddle, built from a found state: the kind is all
    that counts): not a success, and the message counts what there is."""
    from dataclasses import replace

    from taut.sheet import FKResult

    # A team without a rest state (a copy of an obtuse triangle: the object slides off the
    # sheet), so that the direct minimisation of the height supplies none (issue 25).
    sheet = Sheet([[0, 0], [4, 0], [2, 0.6]])
    R = 0.8 * sheet.vertices
    state = forward_kinematics(SheetTeam(SQUARE, 1.0), INNER).lowest
    saddle = FKResult((replace(state, kind="saddle"),), None, "fast", sheet, R, 10.0, None)
    assert (saddle.success, saddle.status) == (False, "infeasible")
    assert saddle.message.startswith(
        "no stable state: 1 solution(s), 1 saddle, 0 not an equilibrium; the object slides "
        "off the sheet")


@pytest.mark.parametrize("backend", BACKENDS)
def test_batch_flags_rows_and_answers_the_rest(backend):
    forms = np.stack([INNER, 2.0 * INNER, 0.8 * SQUARE.vertices])
    solver = FKSolver(SheetTeam(SQUARE, 1.0), backend=backend)
    b = solver.solve_batch(forms)
    assert b.feasible.tolist() == [True, False, True]
    assert b.success.tolist() == [True, False, True] and b.success.dtype == bool
    assert b.status.tolist() == ["ok", "infeasible", "ok"]
    assert b.count.tolist() == [1, 0, 1] and not b.valid[1].any()
    assert np.all(b.kind[1] == -1)
    assert b.message.startswith("2 of 3 formation(s) hold the object in a stable state; "
                                "1 infeasible, the first is formation 1: robots 1 and 2")
    for k in (0, 2):
        one = solver.solve(forms[k])
        np.testing.assert_allclose(b.result(k).lowest.object, one.lowest.object, atol=1e-12)


def test_batch_row_without_a_stable_state_is_flagged():
    forms = np.stack([INNER, INNER])
    b = forward_kinematics_batch(SheetTeam(SQUARE, 0.2), forms)
    assert b.feasible.tolist() == [True, True]
    assert b.success.tolist() == [False, False] and b.status.tolist() == ["infeasible"] * 2
    assert b.message == "0 of 2 formation(s) hold the object in a stable state"
    assert b.result(0).message.startswith("no equilibrium: ")
