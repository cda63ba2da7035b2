"""The active base driving during a carry (taut.cdpr.mission.moving_carry): the moving-anchor
time-optimal law against a brute-force bisection of the constant-speed and
constant-acceleration limits (cable lengths differenced between shifted robots, the
independent tension LP with the base's inertia), and the simulated run re-checked."""

import numpy as np
import pytest
from cdpr_helpers import bisect_largest

from taut.cdpr.mission._execute import run_motion
from taut.cdpr.mission.sites import choose_sites
from taut.io import load_warehouse

from taut.cdpr import (DynamicsModel, distribute_tensions, time_optimal_path, with_box,
                       with_base_acceleration, with_friction, with_stabilisers)
from taut.cdpr.mission._reposition import shifted
from taut.cdpr.mission.moving_carry import moving_carry, run_moving_carry, wheels_for_active
from taut.errors import InvalidInputError

PATH = np.array([[-1.5, 0.0, 0.8], [1.5, 0.0, 0.8]])
A1 = 0.6                        # the active base drives 0.6 m over the 3 m segment
BASE_V, BASE_A = 0.2, 0.25


@pytest.fixture(scope="module")
def deployed(fastkit):
    return with_box(with_friction(with_stabilisers(fastkit), 0.5), 3.0)


def _lengths(robot, pos):
    return np.linalg.norm(robot.exits_world - pos - robot.platform.attach_local, axis=1)


def _inertial(robot, acc):
    mc = robot.platform.mass * robot.platform.com + robot.payload.mass * robot.payload.com
    return -np.concatenate([robot.total_mass * acc, np.cross(mc, acc)])


def _feasible_at(robot, s, a):
    """Independent check at path coordinate s (m) under platform acceleration a (m/s^2):
    robot with the active base shifted and accelerating, the LP with tipping and sliding."""
    d = PATH[1] - PATH[0]
    L = np.linalg.norm(d)
    r = shifted(wheels_for_active(robot), A1 * s / L)
    acc = np.zeros((2, 3))
    acc[0, 0] = A1 / L * a                              # active base: x axis = world x
    r = with_base_acceleration(r, acc)
    pose = np.r_[PATH[0] + s * d / L, 0, 0, 0]
    return distribute_tensions(r, pose, "lp_min_sum", external_wrench=_inertial(r, a * d / L),
                               tipping=True, sliding=True).success


def test_moving_anchor_law_against_brute_force_bisection(deployed):
    dyn = DynamicsModel()
    L = float(np.linalg.norm(PATH[1] - PATH[0]))
    s = np.linspace(0.0, L, 21)
    h = 1e-6

    def speed_ok(v):                                   # winch speed by finite differences
        for si in s:
            r0 = shifted(deployed, A1 * si / L)
            r1 = shifted(deployed, A1 * (si + h) / L)
            p0 = PATH[0] + si * (PATH[1] - PATH[0]) / L
            rate = (_lengths(r1, p0 + h * (PATH[1] - PATH[0]) / L) - _lengths(r0, p0)) / h
            if np.abs(rate).max() * v > dyn.max_cable_speed:
                return False
        return A1 / L * v <= BASE_V
    v_star = bisect_largest(speed_ok, 10.0)
    a_star = bisect_largest(lambda a: A1 / L * a <= BASE_A and all(
        _feasible_at(deployed, si, a) and _feasible_at(deployed, si, -a) for si in s), 10.0)
    carry = moving_carry(deployed, PATH, (0.0, A1), base_accel=BASE_A, base_speed=BASE_V,
                         tension_margin=0.0, tipping_margin=0.0, max_speed=None,
                         max_accel=20.0, smoothing=0.0, grid=40)
    law = carry.law
    assert law.success
    assert v_star == pytest.approx(1.0, rel=1e-3)     # the base's 0.2 m/s binds here
    assert law.peak_speed >= v_star * (1 - 1e-3)
    assert law.peak_speed <= v_star * (1 + 1e-3)
    assert law.duration <= (L / v_star + v_star / a_star) * (1 + 1e-3)
    # the base follows: its speed and acceleration within its limits, at a1 at the end
    track = carry.base_motion.poses[:, 0, 0]
    vb = np.gradient(track, law.times)
    assert np.abs(vb).max() <= BASE_V * (1 + 1e-3)
    assert np.abs(carry.base_acceleration[0, :, 0]).max() <= BASE_A * (1 + 1e-6)
    assert track[-1] - track[0] == pytest.approx(A1)


def test_each_interval_feasible_with_the_base_moving(deployed):
    carry = moving_carry(deployed, PATH, (0.0, A1), base_accel=BASE_A, tension_margin=0.0,
                         tipping_margin=0.0, smoothing=0.0, grid=30)
    law = carry.law
    s = np.linalg.norm(law.grid_positions - PATH[0], axis=1)
    u = np.diff(law.grid_speed ** 2) / np.diff(s)
    for k in range(len(u)):
        assert _feasible_at(deployed, s[k], u[k]) and _feasible_at(deployed, s[k + 1], u[k])


def test_a_standing_base_is_the_fixed_law_on_wheels(deployed):
    still = moving_carry(deployed, PATH, (0.0, 0.0), base_accel=BASE_A)
    fixed = time_optimal_path(wheels_for_active(deployed), PATH)
    assert still.law.duration == pytest.approx(fixed.duration, rel=1e-12)
    # moving makes it slower here: the 0.2 m/s base caps the platform at 1 m/s
    moving = moving_carry(deployed, PATH, (0.0, A1), base_accel=BASE_A)
    assert moving.law.duration > still.law.duration


@pytest.mark.parametrize("kw,field", [({"offsets": (0.0, np.nan)}, "offsets"),
                                      ({"offsets": (0.0,)}, "offsets"),
                                      ({"base_accel": -1.0}, "base_accel"),
                                      ({"base_speed": 0.0}, "base_speed"),
                                      ({"grid": 0}, "grid")])
def test_bad_input_is_named(deployed, kw, field):
    args = {"offsets": (0.0, 0.3), "base_accel": BASE_A} | kw
    offsets = args.pop("offsets")
    with pytest.raises(InvalidInputError, match=field):
        moving_carry(deployed, PATH, offsets, **args)


def test_simulated_run_rechecks_the_constraints():
    wh = load_warehouse("examples/cdpr/warehouse.yaml")
    site = choose_sites(wh).sites[0]
    p, q = site.picks[0], site.places[0]
    lift = np.array([0.0, 0.0, 0.1])
    robot = with_box(site.robot, 4.0)
    wp = np.array([p, p + lift, q + lift])
    carry = moving_carry(robot, wp, (0.0, 0.05), base_accel=wh.max_accel)
    run = run_moving_carry(wh, site.pose, robot, carry)
    assert run.success, run.message
    assert min(run.min_tension_margin, run.min_tipping_margin, run.min_sliding_margin,
               run.min_cable_clearance, run.min_footprint_clearance) >= 0
    # the base's d'Alembert force is in the monitor: the same run with the base's
    # acceleration scaled 40-fold (peak 10 m/s^2: 45 kg x 0.6 m x 10 = 270 N m on an edge)
    # loses most of that on its tipping margin; without it the margin is at least as large
    calm, heavy = (run_motion(wh, site.pose, wheels_for_active(robot), carry.law,
                              DynamicsModel(), carry.base_motion,
                              scale * carry.base_acceleration) for scale in (0.0, 40.0))
    assert calm.min_tipping_margin >= run.min_tipping_margin
    assert heavy.min_tipping_margin < calm.min_tipping_margin - 0.5 * 270.0
    assert not heavy.success
