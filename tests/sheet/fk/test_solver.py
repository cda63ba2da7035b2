"""FKSolver: same answers as forward_kinematics, input checks, closest_stable, frozen
lazy results."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.errors import InfeasibleFormationError, InvalidInputError
from taut.sheet import FKSolver, Sheet, forward_kinematics, forward_kinematics_batch
from taut.sheet.fk import solver
from taut.sheet import random_team
from taut.sheet import SheetTeam


def two_stable_team():
    """A random team with two stable states (seed found by search, checked below)."""
    for seed in range(100):
        sheet, R = random_team(4, np.random.default_rng(seed))
        res = forward_kinematics(SheetTeam(sheet, 2.0 * sheet.size), R)
        if len(res.stable) >= 2:
            return sheet, R, res
    raise AssertionError("no team with two stable states")


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 16), check=st.booleans())
def test_solve_equals_forward_kinematics(seed, n, check):
    sheet, R = random_team(n, np.random.default_rng(seed))
    hold = 1.5 * sheet.size
    a = FKSolver(SheetTeam(sheet, hold, mass=3.0)).solve(R, check=check)
    b = forward_kinematics(SheetTeam(sheet, hold, mass=3.0), R)
    assert [(e.taut, e.kind) for e in a.equilibria] == [(e.taut, e.kind) for e in b.equilibria]
    for x, y in zip(a.equilibria, b.equilibria):
        np.testing.assert_array_equal(x.object, y.object)
        np.testing.assert_array_equal(x.tensions, y.tensions)
    assert a.formation is not R and np.array_equal(a.formation, R)


def test_batch_rows_equal_single_solves():
    sheet, R, _ = two_stable_team()
    forms = np.stack([R, R * 0.98, R * 0.96])
    s = FKSolver(SheetTeam(sheet, 2.0 * sheet.size))
    batch = s.solve_batch(forms)
    ref = forward_kinematics_batch(SheetTeam(sheet, 2.0 * sheet.size), forms)
    np.testing.assert_array_equal(batch.count, ref.count)
    for b in range(3):
        single = s.solve(forms[b])
        assert [e.taut for e in batch.result(b).equilibria] == [e.taut for e in single.equilibria]
        for x, y in zip(batch.result(b).equilibria, single.equilibria):
            np.testing.assert_allclose(x.object, y.object, atol=1e-12 * sheet.size)


@pytest.mark.parametrize("check", [True, False])
def test_torn_formation_raises_with_the_usual_message(check):
    sheet = Sheet.regular(5, 1.0)
    R = sheet.vertices * 1.01
    with pytest.raises(InfeasibleFormationError, match="robots 1 and 2") as exc:
        FKSolver(SheetTeam(sheet, 1.0)).solve(R, check=check)
    assert exc.value.pair == (0, 1)
    bad = np.stack([0.9 * sheet.vertices, R])
    batch = FKSolver(SheetTeam(sheet, 1.0)).solve_batch(bad, check=check)
    assert batch.feasible.tolist() == [True, False] and batch.count[1] == 0
    assert batch.status.tolist() == ["ok", "infeasible"]
    assert "formation 1: robots 1 and 2" in batch.message


@pytest.mark.parametrize("formation, field", [
    (np.zeros((4, 2)), "formation"),            # wrong robot count
    ([[0, 0], [1, 0], [0, np.nan], [1, 1], [0.5, 0.5]], "formation"),
    ("abc", "formation"),
])
def test_bad_formation_is_a_typed_error(formation, field):
    sheet = Sheet.regular(5, 1.0)
    with pytest.raises(InvalidInputError) as exc:
        FKSolver(SheetTeam(sheet, 1.0)).solve(formation)
    assert exc.value.field == field


def test_bad_solver_arguments():
    sheet = Sheet.regular(4, 1.0)
    with pytest.raises(InvalidInputError, match="backend"):
        FKSolver(SheetTeam(sheet, 1.0), backend="gpu")      # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="hold_height"):
        FKSolver(SheetTeam(sheet, -1.0))
    with pytest.raises(InvalidInputError, match="method"):
        FKSolver(SheetTeam(sheet, 1.0), method="magic")     # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="mass"):
        FKSolver(SheetTeam(sheet, 1.0, mass=-1.0))
    with pytest.raises(InvalidInputError, match="team"):
        FKSolver(sheet)                          # type: ignore[arg-type]


@pytest.mark.parametrize("entry", ["solver", "forward_kinematics", "batch"])
def test_subsets_method_takes_at_most_its_team_size(entry):
    """The ``subsets`` limit is the library's (the CLI only reports it): one robot more
    than ``SUBSETS_MAX_ROBOTS`` is refused naming the sheet, on every entry point, before
    any table is built."""
    big = Sheet.regular(solver.SUBSETS_MAX_ROBOTS + 1, 1.0)
    team = SheetTeam(big, 1.0)
    call = {"solver": lambda: FKSolver(team, method="subsets"),
            "forward_kinematics": lambda: forward_kinematics(team, 0.8 * big.vertices,
                                                             method="subsets"),
            "batch": lambda: forward_kinematics_batch(team, [0.8 * big.vertices],
                                                      method="subsets")}[entry]
    with pytest.raises(InvalidInputError, match="at most 40") as exc:
        call()
    assert exc.value.field == "sheet"


def test_without_numba_auto_falls_back_and_numba_is_refused(monkeypatch):
    """Without the compiled kernels ``auto`` answers with numpy and ``numba`` is refused,
    naming the field and saying why (taut._jit.not_compiled_reason)."""
    from taut._jit import not_compiled_reason

    monkeypatch.setattr(solver, "HAVE_NUMBA", False)
    sheet = Sheet.regular(4, 1.0)
    s = FKSolver(SheetTeam(sheet, 1.0))
    assert s.backend == "numpy"
    assert s.solve(0.8 * sheet.vertices).stable
    with pytest.raises(InvalidInputError, match="backend") as err:
        FKSolver(SheetTeam(sheet, 1.0), backend="numba")
    assert str(err.value) == "backend: " + not_compiled_reason()


def test_closest_stable_picks_the_nearest_state():
    sheet, R, res = two_stable_team()
    for e in res.stable:
        assert res.closest_stable(e.object + 1e-3 * sheet.size) is e
        assert res.closest_stable(e.object[:2]) is e
    with pytest.raises(InvalidInputError, match="point"):
        res.closest_stable([1.0, 2.0, 3.0, 4.0])
    flat = forward_kinematics(SheetTeam(sheet, 1e-3 * sheet.size), R)   # too low: nothing hangs
    assert flat.closest_stable([0, 0, 0]) is None


def test_result_is_frozen_and_lazy_length_is_exact():
    sheet, R, _ = two_stable_team()
    res = FKSolver(SheetTeam(sheet, 2.0 * sheet.size)).solve(R)
    n = len(res)
    assert n == len(res.equilibria) == len(res)
    with pytest.raises(AttributeError):
        res.mass = 3.0                           # type: ignore[misc]
    assert "FKResult" in repr(res)
