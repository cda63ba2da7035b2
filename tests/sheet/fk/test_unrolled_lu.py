"""The unrolled 4 x 4 and 5 x 5 solves of the FK kernel (issue 27, batch speed):
``_lu_solve4`` / ``_lu_solve5`` give bit for bit what the looped ``_lu_solve`` gives (same
pivots, same operations in the same order), on random, tied, zero and singular matrices,
so the bordered Lagrange solve (``small._lagrange``) answers as before; and ``shaped``,
the kernels' cheap ``reshape`` of a C-contiguous array, is a view as ``reshape`` is."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.sheet._kernels import linalg as la
from taut.sheet._kernels import small as sk


def _bits(x):
    """The bytes of a float (so that -0.0 != 0.0 and NaN == NaN)."""
    return np.float64(x).tobytes()


def _matrix(rng, n, kind):
    """An ``n`` x ``n`` matrix and right-hand side of the given ``kind``."""
    if kind == "normal":
        K = rng.normal(size=(n, n))
    elif kind == "ties":                          # equal magnitudes: the first one pivots
        K = rng.choice([-2.0, -1.0, 0.0, 1.0, 2.0], size=(n, n))
    elif kind == "scaled":
        K = rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-12, 12, size=(n, 1))
    else:                                          # "bordered": [G 1; 1' 0] with G rank 4
        X = rng.normal(size=(n - 1, 4))
        K = np.ones((n, n))
        K[:n - 1, :n - 1] = X @ np.diag([2.0, 2.0, -2.0, -2.0]) @ X.T
        K[n - 1, n - 1] = 0.0
        if rng.random() < 0.3:                     # two equal robots: singular
            K[1, :] = K[0, :]
            K[:, 1] = K[:, 0]
    rhs = rng.choice([0.0, 1.0, -1.0]) if kind == "ties" else None
    b = rng.normal(size=n) if rhs is None else rng.choice([-1.0, 0.0, 1.0], size=n)
    return K, b


@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.sampled_from([4, 5]),
       kind=st.sampled_from(["normal", "ties", "scaled", "bordered"]))
def test_unrolled_solves_are_bit_identical_to_the_loop(seed, n, kind):
    rng = np.random.default_rng(seed)
    for _ in range(20):
        K, b = _matrix(rng, n, kind)
        rows = [tuple(float(v) for v in np.append(K[i], b[i])) for i in range(n)]
        Kl, bl = K.copy(), b.copy()
        det, ok = la._lu_solve(Kl, bl, n)
        got = (la._lu_solve4 if n == 4 else la._lu_solve5)(*rows)
        assert got[1] == ok
        assert _bits(got[0]) == _bits(det)
        if ok:
            assert [_bits(v) for v in got[2:]] == [_bits(v) for v in bl[:n]]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), s=st.sampled_from([3, 4]))
def test_lagrange_solution_is_the_looped_one(seed, s):
    """``_lagrange`` on 3 or 4 members (unrolled) against the looped solve of the same
    bordered system: same acceptance where the relative determinant decides, same bits."""
    from taut.sheet._tol import SINGULAR_RTOL

    rng = np.random.default_rng(seed)
    X = rng.normal(size=(6, 4))
    G = X @ np.diag([2.0, 2.0, -2.0, -2.0]) @ X.T
    bvec = rng.normal(size=6)
    members = np.full(5, -1, dtype=np.int64)
    members[:s] = np.sort(rng.choice(6, size=s, replace=False))
    lin = np.zeros((13, 6))
    ok = sk._lagrange(G, bvec, members, s, lin[0:6], lin[12], lin[6:12])
    K = np.zeros((6, 6))
    sk._fill_bordered(G, members, s, K)
    norms = np.prod([np.sqrt(sum(v * v for v in K[a, :s + 1])) for a in range(s + 1)])
    rhs = np.append(bvec[members[:s]], 1.0)
    det, solved = la._lu_solve(K, rhs, s + 1)
    if solved and abs(det) > SINGULAR_RTOL * norms:
        assert ok
    if ok:
        assert lin[12, :s + 1].tobytes() == rhs.tobytes()


def test_shaped_is_a_view_like_reshape():
    a = np.arange(12.0)
    v = sk.shaped(a[2:10], (4, 2))
    np.testing.assert_array_equal(v, a[2:10].reshape(4, 2))
    v[1, 0] = -1.0                                 # a view of a, not a copy
    assert a[4] == -1.0
    flat = sk.shaped(np.arange(6).reshape(2, 3), (6,))
    np.testing.assert_array_equal(flat, np.arange(6))
    with pytest.raises(ValueError):
        sk.shaped(a, (5, 2))
