"""Time-optimal platform motion (taut.cdpr.mission.timing): optimality against a
brute-force bisection, feasibility re-checked by the independent tension LP."""

import numpy as np
import pytest
from cdpr_helpers import bisect_largest
from hypothesis import given, settings, strategies as st

from taut.cdpr import (DynamicsModel, cable_state, distribute_tensions, time_optimal_path,
                       with_box, with_friction, with_stabilisers)
from taut.errors import InvalidInputError

PATH = np.array([[-1.5, 0.0, 0.8], [1.5, 0.0, 0.8]])


@pytest.fixture(scope="module")
def deployed(fastkit):
    return with_box(with_friction(with_stabilisers(fastkit), 0.5), 3.0)


def _inertial(robot, acc):
    """Extra wrench of the d'Alembert force for platform accelerations acc (B, 3)."""
    mc = robot.platform.mass * robot.platform.com + robot.payload.mass * robot.payload.com
    return -np.hstack([robot.total_mass * acc, np.cross(mc, acc)])


def _feasible(robot, pos, acc):
    """Independent check: the LP tension distribution with tipping and sliding."""
    P = np.hstack([pos, np.zeros_like(pos)])
    return distribute_tensions(robot, P, "lp_min_sum", external_wrench=_inertial(robot, acc),
                               tipping=True, sliding=True).success


def _cable_speed_ok(robot, pos, vel, limit):
    unit = cable_state(robot, np.hstack([pos, np.zeros_like(pos)])).unit
    return np.abs(np.einsum("bmk,bk->bm", unit, vel)).max(axis=1) <= limit * (1 + 1e-9)


def test_optimal_against_brute_force_bisection(deployed):
    dyn = DynamicsModel()
    pts = PATH[0] + np.linspace(0, 1, 21)[:, None] * (PATH[1] - PATH[0])
    e = (PATH[1] - PATH[0]) / np.linalg.norm(PATH[1] - PATH[0])
    # the largest constant speed whose cable speeds stay within the winch limit everywhere
    v_star = bisect_largest(lambda v: _cable_speed_ok(deployed, pts, np.tile(v * e, (21, 1)),
                                               dyn.max_cable_speed).all(), 10.0)
    # the largest constant acceleration (and deceleration) feasible everywhere, 0 margins
    a_star = bisect_largest(lambda a: _feasible(deployed, pts, np.tile(a * e, (21, 1))).all()
                     and _feasible(deployed, pts, np.tile(-a * e, (21, 1))).all(), 10.0)
    law = time_optimal_path(deployed, PATH, tension_margin=0.0, tipping_margin=0.0,
                            max_speed=None, max_accel=20.0, smoothing=0.0, grid=40)
    assert law.success
    assert law.peak_speed >= v_star * (1 - 1e-6)
    d = float(np.linalg.norm(PATH[1] - PATH[0]))
    trapezoid = d / v_star + v_star / a_star          # accelerate, cruise, decelerate
    assert law.duration <= trapezoid * (1 + 1e-3)
    # the law rides the speed limit somewhere and never exceeds it at the grid points
    assert np.all(law.grid_speed <= law.speed_limit * (1 + 1e-9))


def test_law_feasible_at_every_grid_point(deployed):
    law = time_optimal_path(deployed, PATH, tension_margin=0.0, tipping_margin=0.0,
                            smoothing=0.0, grid=60)
    h = np.linalg.norm(PATH[1] - PATH[0]) / 60
    e = (PATH[1] - PATH[0]) / np.linalg.norm(PATH[1] - PATH[0])
    u = np.diff(law.grid_speed ** 2) / (2 * h)          # the acceleration of each interval
    # each interval's acceleration is admissible at both of its ends
    for ends in (law.grid_positions[:-1], law.grid_positions[1:]):
        assert _feasible(deployed, ends, u[:, None] * e).all()
    lo, hi = law.accel_bounds[:, 0], law.accel_bounds[:, 1]
    assert np.all(lo <= 0) and np.all(hi >= 0)
    assert law.grid_speed[0] == 0 and law.grid_speed[-1] == 0


def test_default_law_feasible_and_within_winch_speed(deployed):
    law = time_optimal_path(deployed, [[0.5, 0, 0.4], [0.5, 0, 1.0], [-1.5, 0, 1.0]])
    sel = slice(None, None, 20)
    assert _feasible(deployed, law.positions[sel], law.accelerations[sel]).all()
    assert _cable_speed_ok(deployed, law.positions[sel], law.velocities[sel],
                           DynamicsModel().max_cable_speed).all()
    assert np.allclose(law.positions[0], [0.5, 0, 0.4]) and np.allclose(law.positions[-1],
                                                                        [-1.5, 0, 1.0])
    assert np.abs(law.velocities[[0, -1]]).max() < 1e-3    # the smoothing's first step
    assert law.segment_times.sum() == pytest.approx(law.duration)


def test_heavier_box_is_not_faster(fastkit):
    robot = with_friction(with_stabilisers(fastkit), 0.5)
    light = time_optimal_path(with_box(robot, 1.0), PATH, smoothing=0.0, max_speed=None,
                              tension_margin=0.0)
    heavy = time_optimal_path(with_box(robot, 5.0), PATH, smoothing=0.0, max_speed=None,
                              tension_margin=0.0)
    assert light.success and heavy.success
    assert light.duration <= heavy.duration + 1e-9


@settings(max_examples=4, deadline=None)
@given(x0=st.floats(-1.5, 1.5), x1=st.floats(-1.5, 1.5), z=st.floats(0.4, 1.0))
def test_random_segments_feasible(deployed, x0, x1, z):
    if abs(x1 - x0) < 0.05:
        return
    law = time_optimal_path(deployed, [[x0, 0, z], [x1, 0, z]], tension_margin=0.0,
                            tipping_margin=0.0, smoothing=0.0, grid=20)
    assert law.success
    k = np.searchsorted(law.times, np.linspace(0, law.duration, 25)[1:-1])
    assert _feasible(deployed, law.positions[k], law.accelerations[k]).all()


def test_refuses_a_pose_that_cannot_rest(deployed):
    law = time_optimal_path(deployed, [[0, 0, 0.8], [0, 0, 2.2]])
    assert not law.success and law.status == "infeasible"
    assert "cannot rest" in law.message


@pytest.mark.parametrize("bad", [[[0, 0, 0.8]], [[0, 0, 0.8], [0, 0, 0.8]],
                                 [[0, 0, np.nan], [0, 0, 1.0]]])
def test_bad_waypoints(deployed, bad):
    with pytest.raises(InvalidInputError):
        time_optimal_path(deployed, bad)


def test_never_slower_than_the_fixed_profile_under_the_same_limits(deployed):
    from taut.cdpr.mission.timing import fixed_profile_duration
    law = time_optimal_path(deployed, [[0.5, 0, 0.4], [0.5, 0, 0.5], [-1.5, 0, 1.0]])
    base = fixed_profile_duration(law, 1.0)
    assert np.isfinite(base) and law.duration <= base
    # a slower cruise is slower still
    assert fixed_profile_duration(law, 0.5) > base
