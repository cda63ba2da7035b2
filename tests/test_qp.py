"""taut._qp: the QP solver (DAQP) and its SLSQP fallback against an exact enumeration of
the active sets, on random instances of the minimum-norm non-negative share problem the
sheet's dependent taut sets solve (min |w|^2 / 2 s.t. E w = r, w >= 0)."""

from itertools import combinations

import numpy as np
import pytest

from taut import _qp

pytest.importorskip("daqp")


def _enumerate(E, r):
    """The minimiser by KKT enumeration: for every set Z of shares held at zero, the
    minimum-norm solution of E w = r with w_Z = 0; the optimum is the feasible one whose
    multipliers of w >= 0 are >= 0 (unique: the problem is strictly convex)."""
    k = E.shape[1]
    best = None
    for size in range(k + 1):
        for Z in combinations(range(k), size):
            F = [j for j in range(k) if j not in Z]
            EF = E[:, F]
            w = np.zeros(k)
            if F:
                w[F] = np.linalg.lstsq(EF, r, rcond=None)[0]
            if np.abs(E @ w - r).max() > 1e-9 or w.min() < -1e-12:
                continue
            # Stationarity w = E' lam + mu: w_F = E_F' lam (the minimum-norm w_F is in
            # that range), and mu_Z = -E_Z' lam must be >= 0.
            lam = np.linalg.lstsq(EF.T, w[F], rcond=None)[0] if F else np.zeros(len(r))
            if Z and (-(E.T @ lam)[list(Z)]).min() < -1e-9:
                continue
            if best is None or w @ w < best @ best - 1e-12:
                best = w
    return best


@pytest.mark.parametrize("seed", range(40))
def test_min_norm_nonnegative_shares_match_the_enumeration(seed):
    g = np.random.default_rng(seed)
    k, rows = int(g.integers(4, 8)), int(g.integers(2, 4))
    E = np.vstack([g.normal(size=(rows - 1, k)), np.ones(k)])
    w_true = np.where(g.random(k) < 0.5, 0.0, g.random(k))     # some shares at zero
    r = E @ (w_true / w_true.sum() if w_true.sum() else np.full(k, 1 / k))
    exact = _enumerate(E, r)
    assert exact is not None
    for backend in ("daqp", "scipy"):
        x = _qp.solve_qp(np.eye(k), A_eq=E, b_eq=r, lb=np.zeros(k), backend=backend,
                         x0=np.full(k, 1 / k))
        assert x is not None, backend
        np.testing.assert_allclose(x, exact, atol=1e-6 if backend == "scipy" else 1e-9,
                                   err_msg=backend)
        assert x.min() >= -1e-10


def test_infeasible_shares_are_refused():
    E = np.vstack([[1.0, 2.0, 3.0], np.ones(3)])
    # E w = (5, 1) with w >= 0 would need 1 w1 + 2 w2 + 3 w3 = 5 > 3 (sum 1): impossible.
    for backend in ("daqp", "scipy"):
        assert _qp.solve_qp(np.eye(3), A_eq=E, b_eq=[5.0, 1.0], lb=np.zeros(3),
                            backend=backend) is None
