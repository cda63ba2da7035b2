"""The set budget covers a batch of poses (issue 24: 1,000 poses of a 12-cable robot's
wrench set through ``axis_capacities`` needed ~19 GB). The sets returned at once hold at
most :data:`taut._validate.MAX_SET_NUMBERS` numbers (a larger batch is refused naming
``poses``), and the functions that reduce each set to a few numbers build the sets a block
of poses at a time, giving what each pose gives alone."""

import numpy as np
import pytest

import taut.cdpr.sets._budget as budget
from taut._validate import MAX_SET_NUMBERS
from taut.cdpr import (available_twist_set, available_wrench_set, axis_capacities,
                       capacity_margin, fastkit_motion_limits, twist_capacities)
from taut.cdpr.deployment.deploy import evaluate_deployment
from taut.errors import InvalidInputError

from cdpr_helpers import random_poses


def _refused(call, poses, facets, what):
    with pytest.raises(InvalidInputError) as err:
        call()
    assert err.value.field == "poses"
    assert f"{poses:,} poses of the {what} ({facets:,} candidate facets each)" \
        in err.value.problem
    assert f"at most {MAX_SET_NUMBERS:,}" in err.value.problem


def test_a_batch_of_sets_past_the_budget_is_refused_naming_the_poses(fastkit):
    """FASTKIT's wrench set has 2,324 candidate facets of 6 + 1 numbers a pose: 1,844
    poses fit in 30 million numbers, 1,845 are refused before any set is built; the same
    for its task-mode twist set."""
    facets = available_wrench_set(fastkit, [0, 0, 1.0]).H.shape[0]
    most = MAX_SET_NUMBERS // (facets * 7)
    assert (facets, most) == (2324, 1844)
    P = np.tile([0.0, 0.0, 1.0, 0.0, 0.0, 0.0], (most + 1, 1))
    _refused(lambda: available_wrench_set(fastkit, P), most + 1, facets, "wrench set")
    facets = available_twist_set(fastkit, [0, 0, 1.0]).H.shape[0]
    most = MAX_SET_NUMBERS // (facets * 7)
    P = np.tile([0.0, 0.0, 1.0, 0.0, 0.0, 0.0], (most + 1, 1))
    _refused(lambda: available_twist_set(fastkit, P), most + 1, facets, "twist set")


def test_axis_capacities_and_margins_take_any_batch_a_block_at_a_time(fastkit, monkeypatch):
    """With a budget of two poses' sets, axis capacities (wrench and twist) and the
    capacity margin of 5 poses are built in blocks (the whole batch's sets would be
    refused) and equal each pose's own result; so does a deployment's twist margin."""
    P = random_poses(fastkit, 5, seed=11)
    lim = fastkit_motion_limits()
    twists = np.array([[0.5, 0, 0, 0, 0, 0], [0, 0, -0.3, 0, 0, 0]])
    alone = [(axis_capacities(fastkit, p), capacity_margin(fastkit, p),
              twist_capacities(fastkit, p, lim)) for p in P]
    wrench_facets = budget.wrench_work(fastkit, True, fastkit.has_sliding)[0]
    monkeypatch.setattr(budget, "MAX_SET_NUMBERS", 2 * wrench_facets * 7)
    with pytest.raises(InvalidInputError, match="poses"):
        available_wrench_set(fastkit, P)
    caps = axis_capacities(fastkit, P)
    margin = capacity_margin(fastkit, P)
    for k, (cap, m, _) in enumerate(alone):
        np.testing.assert_array_equal(caps.positive[k], cap.positive)
        np.testing.assert_array_equal(caps.negative[k], cap.negative)
        np.testing.assert_array_equal(caps.feasible[k], cap.feasible)
        assert margin[k] == m
    twist_facets = available_twist_set(fastkit, P[0], lim).H.shape[0]
    monkeypatch.setattr(budget, "MAX_SET_NUMBERS", 2 * twist_facets * 7)
    with pytest.raises(InvalidInputError, match="poses"):
        available_twist_set(fastkit, P, lim)
    tcaps = twist_capacities(fastkit, P, lim)
    for k, (_, _, tc) in enumerate(alone):
        np.testing.assert_array_equal(tcaps.positive[k], tc.positive)
        np.testing.assert_array_equal(tcaps.negative[k], tc.negative)
    # a deployment's twist margin over 12 points: blocks of 1, 5, 5 and 1 points
    points = random_poses(fastkit, 12, seed=12)[:, :3]
    monkeypatch.undo()
    alone_tm = [evaluate_deployment(fastkit, p[None], None, twists, lim, None)[2]
                for p in points]
    whole_tm = evaluate_deployment(fastkit, points, None, twists, lim, None)[2]
    monkeypatch.setattr(budget, "MAX_SET_NUMBERS",
                        budget.wrench_work(fastkit, True, fastkit.has_sliding)[1])
    assert budget.batch_block(twist_facets, 6) == 5
    assert evaluate_deployment(fastkit, points, None, twists, lim, None)[2] == \
        whole_tm == min(alone_tm)
