"""The per-call path of ``FKSolver.solve`` for the smallest teams (one compiled call,
``_kernels.batch.solve_one``, on a packed solver) gives the results of the general path:
the allocating kernel ``_kernels.small.solve_formation`` with the snap to a similar copy
decided in Python (``FKSolver._rows``, what teams above ``COMPILED_MAX_N`` run), bit for
bit, and the numpy engine within the backend tolerances; on random teams N = 3..5 of
every kind of ``test_backends`` (similar copies of the sheet exactly and within 1e-13..
1e-4, robots on a line or on top of each other, pairs at their limit, ...)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from taut._jit import HAVE_NUMBA
from taut.errors import InfeasibleFormationError, InvalidInputError
from taut.sheet import FKSolver, Sheet, SheetTeam

from test_backends import KINDS, assert_same, make_team

pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="compiled kernels not in use")


def _states(res):
    """Everything a result reports, as plain values (exact comparison)."""
    return ([(e.taut, e.kind, e.object.tolist(), e.contact.tolist(), e.weights.tolist(),
              None if e.tensions is None else e.tensions.tolist(), e.cable_lengths.tolist())
             for e in res.equilibria], res.success, res.status, res.direct, res.message)


def _general(solver, R):
    """The general path of ``solver`` for formation ``R`` (the hull route's composition)."""
    R = np.array(R, dtype=np.float64)
    return solver._result(R, solver._rows(R))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(3, 5),
       hold_ratio=st.sampled_from([0.3, 0.7, 1.0, 2.0, 5.0]),
       mass=st.sampled_from([None, 1.5]))
def test_fast_path_equals_general_path(kind, seed, n, hold_ratio, mass):
    sheet, R = make_team(kind, seed, n)
    team = SheetTeam(sheet, hold_ratio * sheet.size, mass=mass)
    solver = FKSolver(team)
    assert solver._fast
    fast = solver.solve(R)
    assert _states(fast) == _states(_general(solver, R))
    if mass is not None:                      # an independent implementation
        assert_same(fast, FKSolver(team, backend="numpy").solve(R), sheet.size)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 5))
def test_every_input_form_gives_the_same_result(seed, n):
    """Lists, float32, Fortran-ordered and strided float64 arrays take the validating
    route into the same kernel; the result keeps its own copy of the formation."""
    sheet, R = make_team("convex", seed, n)
    solver = FKSolver(SheetTeam(sheet, sheet.size, mass=1.0))
    R = np.ascontiguousarray(R)
    want = _states(solver.solve(R))
    wide = np.zeros((n, 4))
    wide[:, ::2] = R
    for form in (R.tolist(), np.asfortranarray(R), wide[:, ::2], R[None][0]):
        assert _states(solver.solve(form)) == want
    assert _states(solver.solve(R.copy(), check=False)) == want
    single = R.astype(np.float32)
    assert _states(solver.solve(single)) == _states(solver.solve(single.astype(np.float64)))
    res = solver.solve(R)
    R += 1.0                                  # the caller's array changes afterwards
    assert _states(res) == want and not np.shares_memory(res.formation, R)


def test_torn_wrong_shape_and_non_finite_formations_raise():
    sheet = Sheet.regular(4, 1.0)
    solver = FKSolver(SheetTeam(sheet, 1.0))
    with pytest.raises(InfeasibleFormationError):
        solver.solve(1.2 * sheet.vertices)
    bad = 0.8 * sheet.vertices
    bad[2, 1] = np.nan
    with pytest.raises(InvalidInputError):
        solver.solve(bad)
    with pytest.raises(InvalidInputError):
        solver.solve(np.zeros((3, 2)))
    with pytest.raises(InvalidInputError):
        solver.solve(np.zeros((5, 2)), check=False)


def test_return_codes_round_trip():
    from taut.sheet._kernels import batch as bk

    assert bk.decode(7) == (7, 0)
    for k in (0, 1, 13, (1 << bk.FLAGS_SHIFT) - 1):
        for flags in (bk.HAS_STABLE | bk.HAS_PENDING, bk.NEAR_COPY, bk.HAS_PENDING):
            assert bk.decode(-1 - (k | flags << bk.FLAGS_SHIFT)) == (k, flags)
    assert bk.decode(-1 - (bk.TORN << bk.FLAGS_SHIFT))[0] < 0


@pytest.mark.parametrize("n", [3, 4, 5, 8, 12])
def test_pack_holds_the_solver_exactly(n):
    """The packed solver argument reads back as the arrays it was made of (the int64
    candidate table as raw words, never converted)."""
    from taut.sheet._kernels import batch as bk

    solver = FKSolver(SheetTeam(Sheet.regular(n, 2.0), 1.5))
    p = solver._pack
    N, C = int(p[0]), int(p[1])
    assert (N, C) == (n, len(solver._table))
    g = bk.HEADER
    np.testing.assert_array_equal(p[g:g + 2 * N].reshape(N, 2), solver._Vn)
    np.testing.assert_array_equal(p[g + 2 * N:g + 4 * N].reshape(N, 2), solver._A)
    h = g + 4 * N + N * N
    np.testing.assert_array_equal(p[g + 4 * N:h].reshape(N, N), solver._lim2)
    ints = p[h:h + 6 * C].view(np.int64)
    np.testing.assert_array_equal(ints[:5 * C].reshape(C, 5), solver._table)
    np.testing.assert_array_equal(ints[5 * C:], solver._sizes)


def test_kernel_result_fields_made_on_read():
    """A result of the per-call kernel holds its buffer; its rows and formation (the
    kernel's copy of the input, whatever its strides) are made on first read, and it
    pickles and reads back the same."""
    import pickle

    sheet, R = make_team("convex", 5, 4)
    solver = FKSolver(SheetTeam(sheet, sheet.size, mass=1.0))
    R = np.ascontiguousarray(R)
    wide = np.zeros((4, 6))
    wide[:, 1::3] = R
    res = solver.solve(wide[:, 1::3])
    assert "formation" not in vars(res) and "_rows" not in vars(res)
    assert res.formation.tolist() == R.tolist() and res.formation.flags.c_contiguous
    wide[:] = 0.0                                 # the caller's array changes afterwards
    assert res.formation.tolist() == R.tolist()
    want = _states(solver.solve(R))
    assert _states(res) == want
    assert _states(pickle.loads(pickle.dumps(solver.solve(R)))) == want
    with pytest.raises(AttributeError):
        res.not_a_field                           # noqa: B018
