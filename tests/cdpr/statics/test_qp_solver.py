"""Minimum-norm tensions by the QP solver (DAQP, taut._qp): the same optimum as the exact
KKT enumeration where both apply (every preset, tipping on and off), feasible exactly where
the LP is (every preset and a 12-cable model, beyond the enumeration), never worse than
SLSQP, and SLSQP as the fallback when DAQP is missing."""

import numpy as np
import pytest

from taut import _qp
from taut.cdpr import distribute_tensions
from taut.errors import InvalidInputError
from taut.io.cdpr_model import PRESETS, load_cdpr_model

from cdpr_helpers import random_poses, twelve_cable_robot

pytest.importorskip("daqp")


@pytest.fixture(scope="module")
def twelve():
    return twelve_cable_robot()


# Tipping on fastkit_fc (800 poses, the costliest case) in the slow target, which CI runs;
# fastkit_fc without tipping and tipping on the other presets stay in the fast suite.
@pytest.mark.parametrize("tipping, name", [
    pytest.param(t, n, marks=[pytest.mark.slow] if (t, n) == (True, "fastkit_fc") else [])
    for t in (False, True) for n in PRESETS])
def test_daqp_matches_the_enumeration_and_the_lp_on_every_preset(name, tipping):
    robot = load_cdpr_model(name)
    n = 800 if name == "fastkit_fc" else 200         # its 45 N limits: a small workspace
    P = random_poses(robot, n, seed=11 + PRESETS.index(name))
    lp = distribute_tensions(robot, P, "lp_min_sum", tipping=tipping)
    enum = distribute_tensions(robot, P, "qp_min_norm", tipping=tipping,
                               qp_solver="enumeration")
    qp = distribute_tensions(robot, P, "qp_min_norm", tipping=tipping, qp_solver="daqp")
    assert 0 < lp.success.sum() < len(P)                # both answers occur
    np.testing.assert_array_equal(qp.success, lp.success)
    np.testing.assert_array_equal(qp.success, enum.success)
    f = qp.success
    tol = 1e-7 * robot.t_max.max()
    np.testing.assert_allclose(qp.tensions[f], enum.tensions[f], rtol=0, atol=tol)
    np.testing.assert_array_equal(qp.binding, enum.binding)


def test_twelve_cables_feasible_where_the_lp_is_and_never_worse_than_slsqp(twelve):
    assert twelve.m - twelve.dof == 6
    P = random_poses(twelve, 150, seed=4, margin=0.2)
    lp = distribute_tensions(twelve, P, "lp_min_sum")
    qp = distribute_tensions(twelve, P, "qp_min_norm", qp_solver="daqp")
    sq = distribute_tensions(twelve, P, "qp_min_norm", qp_solver="scipy")
    assert 5 < lp.success.sum() < len(P) - 5
    np.testing.assert_array_equal(qp.success, lp.success)
    assert not np.any(sq.success & ~qp.success)          # SLSQP finds nothing DAQP misses
    f = qp.success
    norm = np.linalg.norm(qp.tensions[f], axis=1)
    # The minimum norm: below every other feasible distribution found.
    for other in (lp, sq, distribute_tensions(twelve, P, "lp_min_max")):
        g = other.success[f]
        assert np.all(norm[g] <= np.linalg.norm(other.tensions[f][g], axis=1) + 1e-9)
    both = qp.success & sq.success
    np.testing.assert_allclose(qp.tensions[both], sq.tensions[both], atol=1e-4)
    assert np.all(qp.residual[f] <= 1e-12 * 400)


def test_auto_uses_daqp_beyond_two_redundant_and_slsqp_without_it(twelve, monkeypatch):
    P = random_poses(twelve, 40, seed=8, margin=0.2)
    auto = distribute_tensions(twelve, P, "qp_min_norm")
    daqp = distribute_tensions(twelve, P, "qp_min_norm", qp_solver="daqp")
    np.testing.assert_array_equal(auto.tensions, daqp.tensions)
    monkeypatch.setattr(_qp, "_daqp", lambda: None)           # DAQP not installed
    assert _qp.qp_backend() == "scipy"
    fallback = distribute_tensions(twelve, P, "qp_min_norm")
    scipy = distribute_tensions(twelve, P, "qp_min_norm", qp_solver="scipy")
    np.testing.assert_array_equal(fallback.tensions, scipy.tensions)
    with pytest.raises(ModuleNotFoundError) as err:
        distribute_tensions(twelve, P, "qp_min_norm", qp_solver="daqp")
    assert err.value.name == "daqp"


def test_enumeration_refuses_more_than_two_redundant(twelve):
    with pytest.raises(InvalidInputError) as err:
        distribute_tensions(twelve, [0, 0, 2.0], "qp_min_norm", qp_solver="enumeration")
    assert err.value.field == "qp_solver"


@pytest.mark.parametrize("backend", ["daqp", "scipy"])
def test_solve_qp_on_a_hand_checked_problem(backend):
    # min 1/2 |x|^2 s.t. x0 + x1 + x2 = 3, x2 <= 0.5, x >= 0: x = (1.25, 1.25, 0.5).
    x = _qp.solve_qp(np.eye(3), A_eq=np.ones((1, 3)), b_eq=[3.0], A_ub=[[0.0, 0, 1]],
                     b_ub=[0.5], lb=np.zeros(3), backend=backend)
    np.testing.assert_allclose(x, [1.25, 1.25, 0.5], atol=1e-7)
    # Infeasible: x >= 0 and x0 + x1 + x2 = -1.
    assert _qp.solve_qp(np.eye(3), A_eq=np.ones((1, 3)), b_eq=[-1.0], lb=np.zeros(3),
                        backend=backend) is None
