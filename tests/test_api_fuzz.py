"""Hypothesis fuzz of the public Python API: every call with a generated wrong (or odd but
valid) argument either raises a :class:`taut.errors.TautError` subclass naming a field or
returns a valid result — never a bare ``IndexError``/``AttributeError``/``ZeroDivisionError``,
never a result holding ``inf`` where a number was promised."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from taut.errors import TautError
from taut.io import load_cdpr_model
from taut.plan import generate_scenario
from taut.sheet import Sheet, forward_kinematics, forward_kinematics_batch, inverse_kinematics
from taut.sheet import SheetTeam
from taut.cdpr import (available_wrench_set, axis_capacities, distribute_tensions,
                       wrench_feasible)

SHEET = Sheet.regular(4, 1.0)
TEAM = SheetTeam(SHEET, 1.0)
FORMATION = 0.8 * np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
ROBOT = load_cdpr_model("fastkit")

#: Values in place of a number or array: NaN/inf/huge, wrong types, empty, wrong shapes.
odd_scalars = st.one_of(
    st.sampled_from([float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 0.0, -1.0,
                     True, False, None, "abc", b"\x00", [], (), {}, object()]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**12, max_value=10**12))
odd_arrays = st.one_of(
    odd_scalars,
    st.sampled_from([np.empty((0,)), np.empty((0, 2)), np.empty((0, 4, 2)), np.empty((0, 6)),
                     np.zeros((3, 3, 3, 3)), [[1.0]], [[1.0, 2.0, 3.0]] * 4,
                     [["a", "b"]] * 4, np.full((4, 2), np.nan), np.full((4, 2), 1e308)]),
    st.lists(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64),
                      min_size=0, max_size=7), min_size=0, max_size=9))
models = st.sampled_from([None, "fastkit", 3, [], object()])


def _check(call):
    """Run ``call``; a TautError must name a field, anything else must not be raised."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            return call()
        except TautError as exc:
            assert exc.field and exc.problem and str(exc).startswith(exc.field)
            return None


def _finite_or_absent(x):
    if x is None:
        return
    a = np.asarray(x, dtype=float)
    assert not np.any(np.isinf(a)), a


_FAST = settings(max_examples=40, deadline=None,
                 suppress_health_check=[HealthCheck.too_slow])


@_FAST
@given(formation=odd_arrays, hold=odd_scalars, mass=st.one_of(st.none(), odd_scalars))
def test_forward_kinematics(formation, hold, mass):
    r = _check(lambda: forward_kinematics(SheetTeam(SHEET, hold, mass=mass), formation))
    if r is not None:
        for e in r.equilibria:
            _finite_or_absent(e.tensions)
            assert 0 < e.object[2] < r.hold_height


@_FAST
@given(formations=odd_arrays, hold=odd_scalars)
def test_forward_kinematics_batch(formations, hold):
    _check(lambda: forward_kinematics_batch(SheetTeam(SHEET, hold), formations))


@_FAST
@given(sheet=st.one_of(models, odd_arrays))
def test_models_in_wrong_places(sheet):
    _check(lambda: SheetTeam(sheet, 1.0))
    _check(lambda: forward_kinematics(sheet, FORMATION))
    _check(lambda: inverse_kinematics(sheet, (0.0, 0.0, 0.3)))


@_FAST
@given(target=odd_arrays, hold=odd_scalars)
def test_inverse_kinematics(target, hold):
    _check(lambda: inverse_kinematics(SheetTeam(SHEET, hold), target))


@_FAST
@given(n=odd_scalars, radius=odd_scalars)
def test_sheet_regular(n, radius):
    s = _check(lambda: Sheet.regular(n, radius))
    if s is not None:
        assert 3 <= s.n <= 1000 and np.all(np.isfinite(s.vertices))


@_FAST
@given(poses=odd_arrays, robot=st.one_of(models, st.just(ROBOT)))
def test_cdpr_statics(poses, robot):
    r = _check(lambda: distribute_tensions(robot, poses))
    if r is not None:
        assert r.tensions.shape[0] >= 1
    _check(lambda: available_wrench_set(robot, poses))
    _check(lambda: axis_capacities(robot, poses))


@_FAST
@given(chunk=odd_scalars)
def test_wrench_feasible_chunk(chunk):
    r = _check(lambda: wrench_feasible(ROBOT, [[0.0, 0.0, 1.0]], chunk=chunk))
    if r is not None:                      # the answer cannot depend on the block size
        assert r.tolist() == wrench_feasible(ROBOT, [[0.0, 0.0, 1.0]]).tolist()


@_FAST
@given(seed=odd_scalars, n=st.one_of(st.none(), odd_scalars))
def test_generate_scenario(seed, n):
    _check(lambda: generate_scenario(seed, n))


def test_lists_tuples_ints_are_arrays():
    """Where arrays are documented, lists, tuples and ints give the same answer."""
    a = forward_kinematics(SheetTeam(SHEET, 1.0), FORMATION)
    b = forward_kinematics(SheetTeam(SHEET, 1), tuple(map(tuple, FORMATION.tolist())))
    assert [e.taut for e in a.equilibria] == [e.taut for e in b.equilibria]
    np.testing.assert_allclose([e.object for e in a.equilibria],
                               [e.object for e in b.equilibria])
    t1 = distribute_tensions(ROBOT, np.array([0.0, 0.0, 1.0]))
    t2 = distribute_tensions(ROBOT, [0, 0, 1])
    np.testing.assert_allclose(t1.tensions, t2.tensions)


@pytest.mark.parametrize("call, field", [
    (lambda: forward_kinematics_batch(TEAM, np.empty((0, 4, 2))), "formations"),
    (lambda: distribute_tensions(None, [0, 0, 1]), "robot"),
    (lambda: distribute_tensions(ROBOT, np.empty((0, 6))), "pose"),
    (lambda: generate_scenario(0, 0), "n_robots"),
    (lambda: Sheet.regular(10**7, 1), "n"),
    (lambda: wrench_feasible(ROBOT, [[0, 0, 1]], chunk=-1), "chunk"),
    (lambda: Sheet([[1e308, 0], [0, 1], [1, 1]]), "sheet"),
])
def test_issue_examples_are_typed_errors(call, field):
    with pytest.raises(TautError) as exc:
        call()
    assert exc.value.field == field
