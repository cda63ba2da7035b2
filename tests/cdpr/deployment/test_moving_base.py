"""Deployment with the active base moving during the task (piecewise-constant schedule)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.cdpr import (lift_bound, place_bases, plan_moving_deployment, staged_lift_bound,
                       with_stabilisers, wrench_feasible)
from taut.cdpr.deployment.moving_base import slice_box
from taut.errors import InvalidInputError

FULL = [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]]


@settings(max_examples=30, deadline=None)
@given(x0=st.floats(-3, 2), w=st.floats(0.1, 4), k=st.integers(1, 9))
def test_slices_partition_the_box(x0, w, k):
    box = np.array([[x0, -0.1, 0.2], [x0 + w, 0.3, 1.0]])
    s = slice_box(box, k)
    assert s.shape == (k, 2, 3)
    np.testing.assert_allclose(s[:, 1, 0] - s[:, 0, 0], w / k)
    np.testing.assert_allclose(s[1:, 0, 0], s[:-1, 1, 0])        # shared faces
    assert s[0, 0, 0] == box[0, 0] and s[-1, 1, 0] == box[1, 0]
    np.testing.assert_array_equal(s[:, :, 1:], np.broadcast_to(box[:, 1:], (k, 2, 2)))


def test_staged_certificate_is_the_worst_slice(fastkit):
    one = staged_lift_bound(fastkit, FULL, 1)
    assert one.bound == pytest.approx(lift_bound(fastkit, FULL).bound, rel=1e-12)
    two = staged_lift_bound(fastkit, FULL, 2)
    per = [lift_bound(fastkit, b, samples=(22, 5)) for b in slice_box(np.array(FULL), 2)]
    assert two.bound == pytest.approx(min(c.bound for c in per), rel=1e-12)
    # a moving base weakens the certificate (one placement per slice, not per box) ...
    assert two.bound > one.bound
    # ... yet two stages still cannot lift the preset's 12 kg at z = 2.2 m
    assert two.refutes


def test_refuted_schedule_is_not_searched(fastkit):
    res = plan_moving_deployment(with_stabilisers(fastkit), FULL, stages=2)
    assert not res.success and res.status == "refuted" and res.refuted
    assert res.evaluations == 0 and res.stages == () and "N" in res.message


@pytest.mark.parametrize("kw", [{"stages": 0}, {"stages": 2.5}, {"transitions": -1}])
def test_bad_settings_are_typed_errors(fastkit, kw):
    with pytest.raises(InvalidInputError):
        plan_moving_deployment(fastkit, [[-1, -0.05, 0.3], [1, 0.05, 0.8]], **kw)


@pytest.mark.slow
def test_schedule_is_verified_stage_by_stage(fastkit):
    """Independent re-check: every stage's points with its bases, the passive base fixed
    over the task, the footprint rule per slice."""
    robot = with_stabilisers(fastkit)
    box = [[-2.0, -0.05, 0.3], [2.0, 0.05, 0.8]]
    res = plan_moving_deployment(robot, box, stages=2, maxiter=1, popsize=2, grid=(3, 1, 2),
                                 verify_grid=(7, 2, 3), search=(1.0, 0.3, 0.3))
    assert len(res.stages) == 2 and res.transition_feasible.shape == (1,)
    p0, p1 = res.base_poses
    np.testing.assert_array_equal(p0["passive"], p1["passive"])
    for k, stage in enumerate(res.stages):
        rr = place_bases(robot, res.base_poses[k])
        pts = stage.points
        assert np.all(pts[:, 0] >= res.slices[k, 0, 0] - 1e-12)
        assert np.all(pts[:, 0] <= res.slices[k, 1, 0] + 1e-12)
        np.testing.assert_array_equal(wrench_feasible(rr, pts, tipping=True),
                                      stage.point_feasible)
    assert res.success == (all(s.success for s in res.stages)
                           and bool(res.transition_feasible.all()))
