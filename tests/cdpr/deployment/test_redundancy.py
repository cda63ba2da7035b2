"""Redundancy resolution of FASTKIT in task mode (active base + 8 cables, 11 joints)."""

import numpy as np
import pytest

from taut.cdpr import resolve_redundancy
from taut.cdpr import MotionLimits, first_order_model, twist_capacities
from taut.errors import InvalidInputError

POSE = np.array([0.3, 0.0, 1.0, 0.0, 0.0, 0.05])
LO = np.r_[-0.2, -0.2, -0.2, np.full(8, -2.0)]
HI = -LO


def _check(fastkit, res, t, scale=1.0):
    fom = first_order_model(fastkit, POSE)
    assert np.all(res.q_dot >= LO - 1e-8) and np.all(res.q_dot <= HI + 1e-8)
    np.testing.assert_allclose(fom.A @ (scale * t), fom.B @ res.q_dot, atol=1e-8)
    assert res.residual < 1e-8


@pytest.mark.parametrize("objective", ["min_norm", "least_base"])
def test_feasible_twists_are_reproduced_within_limits(fastkit, objective):
    g = np.random.default_rng(5)
    for _ in range(6):
        t = g.normal(size=6) * [0.3, 0.3, 0.3, 0.2, 0.2, 0.2]
        res = resolve_redundancy(fastkit, POSE, t, objective=objective)
        assert res.success and res.scale == 1.0 and res.status == "ok"
        _check(fastkit, res, t)


def test_least_base_keeps_bases_still_when_cables_suffice(fastkit):
    t = np.array([0.5, 0.2, -0.1, 0.0, 0.05, 0.1])
    lb = resolve_redundancy(fastkit, POSE, t, objective="least_base")
    mn = resolve_redundancy(fastkit, POSE, t, objective="min_norm")
    assert np.allclose(lb.base_rates, 0.0, atol=1e-7)
    # the min-norm solution trades base motion for smaller cable speeds
    w = 1.0 / HI
    assert np.sum((mn.q_dot * w) ** 2) <= np.sum((lb.q_dot * w) ** 2) + 1e-9


def test_twist_needing_the_base(fastkit):
    """Between the fixed-base and moving-base capacity along x the base must move."""
    mv = twist_capacities(fastkit, POSE).positive[0]
    fx = twist_capacities(fastkit, POSE, moving=()).positive[0]
    assert mv > fx
    t = np.array([0.5 * (mv + fx), 0, 0, 0, 0, 0])
    res = resolve_redundancy(fastkit, POSE, t, objective="least_base")
    assert res.success
    assert np.abs(res.base_rates).max() > 1e-4
    _check(fastkit, res, t)
    fixed = resolve_redundancy(fastkit, POSE, t, moving=())
    assert not fixed.success and fixed.scale == pytest.approx(fx / t[0], rel=1e-6)


def test_infeasible_twist_reports_largest_fraction(fastkit):
    cap = twist_capacities(fastkit, POSE).positive[2]
    t = np.array([0, 0, 1.25 * cap, 0, 0, 0])
    res = resolve_redundancy(fastkit, POSE, t)
    assert not res.success
    assert res.scale == pytest.approx(0.8, rel=1e-6)
    assert "outside the available twist set" in res.message
    assert res.status == "infeasible"
    _check(fastkit, res, t, scale=res.scale)


def test_limits_excluding_rest():
    from taut.io.cdpr_model import load_cdpr_model
    robot = load_cdpr_model("fastkit")
    lim = MotionLimits(cable_min=0.5, cable_max=1.0)
    res = resolve_redundancy(robot, POSE, np.zeros(6), lim)
    assert not res.success and "standing still" in res.message


def test_navigation_mode(fastkit):
    ok = resolve_redundancy(fastkit, POSE, [0.1, -0.1, 0, 0, 0, 0.01], mode="navigation")
    assert ok.success and np.allclose(ok.cable_speeds, 0.0)
    assert ok.q_dot.shape == (3,) and np.all(np.abs(ok.q_dot) <= 0.2 + 1e-12)
    lift = resolve_redundancy(fastkit, POSE, [0, 0, 0.1, 0, 0, 0], mode="navigation")
    assert not lift.success and "planar" in lift.message
    fast = resolve_redundancy(fastkit, POSE, [0.4, 0, 0, 0, 0, 0], mode="navigation")
    assert not fast.success and fast.scale == pytest.approx(0.5)


def test_bad_input(fastkit):
    with pytest.raises(InvalidInputError):
        resolve_redundancy(fastkit, POSE, [1, 2, 3])
    with pytest.raises(InvalidInputError):
        resolve_redundancy(fastkit, POSE, [np.nan, 0, 0, 0, 0, 0])
    with pytest.raises(InvalidInputError, match="objective"):
        resolve_redundancy(fastkit, POSE, np.zeros(6), objective="fastest")
    with pytest.raises(InvalidInputError, match="ghost"):
        resolve_redundancy(fastkit, POSE, np.zeros(6), moving=("ghost",))


@pytest.mark.parametrize("objective", ["min_norm", "least_base"])
def test_the_qp_solver_and_its_slsqp_fallback_agree(fastkit, objective, monkeypatch):
    """DAQP (taut._qp) and SciPy's SLSQP (the fallback without it) solve the same convex
    QP: the same joint rates, both within limits, DAQP's objective never above SLSQP's."""
    pytest.importorskip("daqp")
    from taut import _qp
    from taut.cdpr._tol import LEAST_BASE_CABLE_WEIGHT
    g = np.random.default_rng(17)
    cap = twist_capacities(fastkit, POSE).positive[0]
    twists = [g.normal(size=6) * [0.3, 0.3, 0.3, 0.2, 0.2, 0.2] for _ in range(6)]
    twists.append(np.array([0.9 * cap, 0, 0, 0, 0, 0]))            # needs the base
    solved = [resolve_redundancy(fastkit, POSE, t, objective=objective) for t in twists]
    monkeypatch.setattr(_qp, "_daqp", lambda: None)                  # DAQP not installed
    fallback = [resolve_redundancy(fastkit, POSE, t, objective=objective) for t in twists]
    w = 1.0 / HI
    cable_w = 1.0 if objective == "min_norm" else LEAST_BASE_CABLE_WEIGHT
    weight = np.r_[w[:3], cable_w * w[3:]]
    for t, a, b in zip(twists, solved, fallback):
        assert a.success and b.success
        _check(fastkit, a, t)
        _check(fastkit, b, t)
        fa, fb = np.sum((a.q_dot * weight) ** 2), np.sum((b.q_dot * weight) ** 2)
        assert fa <= fb * (1 + 1e-7) + 1e-18
        np.testing.assert_allclose(a.base_rates, b.base_rates, atol=1e-5)
