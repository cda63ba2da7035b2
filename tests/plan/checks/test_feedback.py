"""Feedback on the object (issue 28 part 3): the closed loop against open loop on the same
robot errors, the open loop being the robustness analysis's replay."""

from __future__ import annotations

import numpy as np
import pytest

from taut.errors import InvalidInputError, PlanningError
from taut.plan import generate_suite, object_feedback, plan
from taut.plan.checks import feedback as fb
from taut.plan.checks.robustness import position_error, replay
from taut.plan.result import failure


def test_options_are_validated_and_a_failed_plan_refused():
    scenario = generate_suite(1)[0]
    with pytest.raises(PlanningError):
        object_feedback(failure(scenario, "no plan", "disc"))
    for field, value in (("gain", 0.0), ("gain", 2.0), ("damping", -1.0),
                         ("measurement_noise_m", np.nan), ("robot_error_m", 2.0)):
        with pytest.raises(InvalidInputError, match=field):
            object_feedback(failure(scenario, "no plan", "disc"), **{field: value})


@pytest.fixture(scope="module")
def small_plans():
    """Plans of the suite's first two three-robot scenarios (a few seconds each)."""
    suite = generate_suite(7)
    plans = [plan(suite[i]) for i in (0, 6)]
    assert all(p.success for p in plans)
    return plans


@pytest.mark.slow
def test_open_loop_is_the_robustness_replay(small_plans):
    """Gain 0 is the open loop: the same deviations as plan_robustness's replay of the
    same errors (the stepping simulator against the whole-run simulation)."""
    result = small_plans[0]
    R, times = np.asarray(result.robots), np.asarray(result.times)
    planned = np.asarray(result.object)
    errors = position_error(np.random.default_rng(0), times, R.shape[1], 0.005, "disc", 1.0)
    model = fb._plan_model(result, 0.1)
    keep = np.full((len(R), R.shape[1] * (R.shape[1] - 1) // 2), -np.inf)
    trial, dev, _ = fb._run(result.scenario, R, planned, model, errors,
                            np.zeros((len(R) + 20, 3)), 0.0, keep)
    ref = replay(result.scenario, R + errors, planned)
    assert (trial.torn, trial.dropped) == (ref.torn, ref.dropped)
    assert trial.deviation == pytest.approx(ref.deviation, rel=1e-9, abs=1e-12)


@pytest.mark.slow
def test_closed_loop_halves_the_deviation_without_more_failures(small_plans):
    """On a subset of the suite under 5 mm robot error: the median object deviation at
    least halves, with no more tears or drops than open loop."""
    for result in small_plans:
        out = object_feedback(result, trials=3, seed=1)
        assert out.success, out.message
        assert out.median_closed_m <= 0.5 * out.median_open_m, out.message
        assert out.closed_tears <= out.open_tears and out.closed_drops <= out.open_drops
        assert out.open_samples_m.shape == (3, len(result.times))
