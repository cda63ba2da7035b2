"""The per-call path's direct call into the compiled specialisation (issue 27, "the
smallest teams fastest"): ``FKSolver``'s specialised ``solve_one`` returns what numba's
dispatcher returns and only ever receives the arrays it was specialised for; and the
kernel's bordered Lagrange solve keeps its singularity policy (relative determinant, then
condition number) against numpy's determinant and singular values."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from taut._jit import HAVE_NUMBA
from taut.sheet import FKSolver, SheetTeam
from taut.sheet._kernels import small as sk

from test_backends import KINDS, make_team


def _bordered(G, members):
    """The bordered matrix ``[G_S 1; 1' 0]`` of ``members`` (numpy)."""
    s = len(members)
    K = np.zeros((s + 1, s + 1))
    K[:s, :s] = G[np.ix_(members, members)]
    K[:s, s] = K[s, :s] = 1.0
    return K


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), s=st.integers(3, 5), log_eps=st.floats(-15.0, -5.0))
def test_lagrange_keeps_its_singularity_policy(seed, s, log_eps):
    """Two robots whose rows of the Gram matrix differ by ``eps``: the bordered system
    is well posed, suspect (relative determinant under ``SINGULAR_RTOL``) but accepted
    (condition number under ``MAX_CONDITION``) or refused, as numpy's determinant and
    singular values say (borderline cases skipped); an accepted one is solved."""
    from taut.sheet._tol import MAX_CONDITION, SINGULAR_RTOL

    rng = np.random.default_rng(seed)
    X = rng.normal(size=(6, 4))
    X[1] = X[0]
    G = X @ np.diag([2.0, 2.0, -2.0, -2.0]) @ X.T          # as _frame's Gram matrix
    G[1, 1] += 10.0 ** log_eps
    b = rng.normal(size=6)
    members = np.full(5, -1, dtype=np.int64)
    members[:s] = np.arange(s)
    K = _bordered(G, members[:s])
    rel = abs(np.linalg.det(K)) / np.prod(np.linalg.norm(K, axis=1))
    sv = np.linalg.svd(K, compute_uv=False)
    cond = max(sv.max(), 1.0) / min(sv.min(), 1.0)
    assume(not (SINGULAR_RTOL / 4 < rel < 4 * SINGULAR_RTOL))
    assume(not (MAX_CONDITION / 4 < cond < 4 * MAX_CONDITION))
    lin = np.empty((13, 6))
    ok = sk._lagrange(G, b, members, s, lin[0:6], lin[12], lin[6:12])
    assert ok == (rel > SINGULAR_RTOL or cond < MAX_CONDITION)
    if ok:
        want = np.linalg.solve(K, np.append(b[:s], 1.0))
        np.testing.assert_allclose(lin[12, :s + 1], want, rtol=0,    # backward stable
                                   atol=1e-13 * cond * np.abs(want).max())


@pytest.mark.skipif(not HAVE_NUMBA, reason="compiled kernels not in use")
@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(3, 5))
def test_specialised_call_returns_what_the_dispatcher_returns(kind, seed, n):
    from taut.sheet._kernels import batch as bk

    sheet, R = make_team(kind, seed, n)
    solver = FKSolver(SheetTeam(sheet, sheet.size))
    assert solver._fast and solver._solve_one is not bk.solve_one
    R = np.array(R, dtype=np.float64)
    mine, theirs = np.empty(solver._out_shape), np.empty(solver._out_shape)
    code = solver._solve_one(R, solver._pack, mine)
    assert code == bk.solve_one(R, solver._pack, theirs)
    rows = bk.decode(code)[0]
    np.testing.assert_array_equal(mine[:max(rows, 0)], theirs[:max(rows, 0)])


@pytest.mark.skipif(not HAVE_NUMBA, reason="compiled kernels not in use")
def test_arrays_the_specialised_call_was_not_made_for_take_the_converting_route():
    """The specialised call checks no type: big-endian and subclass formations reach it
    only as fresh native float64 copies; read-only, unaligned and strided float64 ones
    as they are (it reads any strides and copies them first); the same result."""
    sheet, R = make_team("convex", 11, 4)
    solver = FKSolver(SheetTeam(sheet, sheet.size, mass=1.0))
    R = np.ascontiguousarray(R, dtype=np.float64)
    want = solver.solve(R)
    frozen = R.copy()
    frozen.flags.writeable = False
    raw = np.zeros(R.nbytes + 1, dtype=np.uint8)[1:].view(np.float64).reshape(R.shape)
    raw[:] = R                                         # unaligned storage
    for form in (R.astype(">f8"), frozen, raw, R.view(np.matrix)):
        got = solver.solve(form)
        assert [e.taut for e in got.equilibria] == [e.taut for e in want.equilibria]
        for a, b in zip(got.equilibria, want.equilibria):
            assert np.array_equal(a.object, b.object) and np.array_equal(a.weights, b.weights)
        assert got.formation.dtype == np.float64 and got.formation.flags.c_contiguous
        assert type(got.formation) is np.ndarray and got.formation.flags.aligned
