"""The linearised robustness screen before the formation admission's sampling (issue 28):
it rejects only what the sampling rejects too, and the planner's plans do not change."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from taut.plan import _options, formation_library, generate_scenario, plan
from taut.plan.formations._squeeze_robust import linear_rejects, tolerates
from taut.sheet import FKSolver, object_covariance

ACCURACY = 5e-3


@pytest.fixture(scope="module")
def narrow():
    """Scenario 2 of the seed-2024 suite (5 robots: with six or more taut cables the
    jacobian is NaN and nothing is screened), its narrow formation's solver, robots and
    state."""
    sc = generate_scenario(2026, 5)
    _, others, _ = formation_library(sc, sheet_margin=0.01)
    f = next(f for f in others if f.kind == "narrow")
    solver = FKSolver(sc.team.carrier)
    R = np.ascontiguousarray(f.robots, dtype=float)
    e = min(solver.solve(R).stable, key=lambda e: abs(e.height - f.object_height))
    cov = object_covariance(e, ACCURACY ** 2 / 4)
    return solver, R, e, np.sqrt(cov[2, 2]), np.sqrt(np.trace(cov))


@pytest.fixture
def no_screen(monkeypatch):
    monkeypatch.setattr(_options, "LINEAR_SCREEN",
                        dataclasses.replace(_options.LINEAR_SCREEN, enabled=False))


def test_what_the_screen_rejects_the_sampling_rejects(narrow, no_screen):
    solver, R, e, s_z, s = narrow
    assert 0 < s_z and 0 < s < 0.05                    # a finite, millimetre-scale prediction
    # height: half a predicted deviation of room is rejected by both, five accepted by both
    low = e.height - 0.5 * s_z
    assert linear_rejects(e, low, np.inf, 1.0)
    assert not tolerates(solver, R, e, low, max_shift=np.inf)
    high = e.height - 5 * s_z
    assert not linear_rejects(e, high, np.inf, 1.0)
    assert tolerates(solver, R, e, high, max_shift=np.inf)
    # shift: half the predicted root mean square shift is rejected by both
    assert linear_rejects(e, 0.0, 0.5 * s, 1.0)
    assert not tolerates(solver, R, e, 0.0, max_shift=0.5 * s)
    assert not linear_rejects(e, 0.0, 5 * s, 1.0)


def test_a_disabled_screen_is_not_consulted(narrow, no_screen, monkeypatch):
    from taut.plan.formations import _squeeze_robust

    def boom(*a, **k):
        raise AssertionError("screen consulted")

    monkeypatch.setattr(_squeeze_robust, "linear_rejects", boom)
    solver, R, e, _, _ = narrow
    assert tolerates(solver, R, e, 0.0, max_shift=np.inf, draws=3)


@pytest.mark.slow
def test_plans_are_identical_with_and_without_the_screen(monkeypatch):
    """Scenario 3 of the suite needs a squeezed formation (many admission calls)."""
    from taut.plan import planner
    from taut.plan.formations import library
    sc = generate_scenario(2027, 6)
    out = []
    for enabled in (True, False):
        monkeypatch.setattr(_options, "LINEAR_SCREEN",
                            dataclasses.replace(_options.LINEAR_SCREEN, enabled=enabled))
        library._library.cache_clear()
        library._squeezed.cache_clear()
        planner._bypass.cache_clear()
        out.append(plan(sc))
    a, b = out
    assert a.status == b.status and a.success
    np.testing.assert_array_equal(a.robots, b.robots)
    np.testing.assert_array_equal(a.times, b.times)
