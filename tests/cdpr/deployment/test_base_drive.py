"""A physical deployment drive (issue 26 item 5): the active base drives on its wheels with
its stabilisers retracted, the tensions keep every base upright, the stabilisers deploy once
in place; a drive no tension distribution can hold upright is reported, naming where.

The "no" answers are checked by an independent algorithm (the min-max LP, HiGHS, against
the plan's min-norm QP), the "yes" answers by recomputing statics and edge moments."""

from dataclasses import fields

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.cdpr import (BaseMotion, VelocityController, distribute_tensions, plan_base_drive,
                       reference_from_samples, simulate, tipping_moments, with_stabilisers)
from taut.cdpr.control._setup import _robot_at
from taut.cdpr.deployment.moving_base import (BaseDrivePlan, MovingDeploymentResult,
                                              _stabilisers, _transition_wait)
from taut.cdpr.kinematics.cables import gravity_wrench, rotation_matrices, wrench_matrix
from taut.cdpr.workspace.wrench_feasible import grid_points
from taut.errors import InfeasiblePoseError, InvalidInputError

LOW = [0.3, 0.0, 0.7, 0.0, 0.0, 0.0]       # held during the drive: feasible on wheels
HIGH = [0.3, 0.0, 1.0, 0.0, 0.0, 0.0]      # not: the issue's -38 N m edge
TOL_NM = 1e-6                              # N m: solver round-off on edge moments


@pytest.fixture(scope="module")
def robot():
    from taut.io.cdpr_model import load_cdpr_model
    return with_stabilisers(load_cdpr_model("fastkit"))


@pytest.fixture(scope="module")
def drive(robot):
    """The example's drive (examples/cdpr/fastkit_base_drive.py): 0.5 m towards the platform
    in 5 s from t = 0.2 s."""
    return BaseMotion.line(robot, "active", (0.5, 0.0, 0.0), duration=5.0, start=0.2,
                           samples=21)


def _lp_holds(robot, pose):
    """Independent of the plan's QP: the min-max LP with the tipping rows."""
    return bool(distribute_tensions(robot, pose, "lp_min_max", tipping=True).success)


def _area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))


def _check_held(plan, pose):
    """Statics, tension limits and edge moments of every planned sample, recomputed."""
    R = rotation_matrices(np.asarray(pose, float)[None, 3:])[0]
    for i, bp in enumerate(plan.base_poses_m_rad):
        at = _robot_at(plan.drive_robot, bp)
        t = plan.tensions_N[i]
        assert np.all(t >= at.t_min - 1e-9) and np.all(t <= at.t_max + 1e-9)
        np.testing.assert_allclose(-tipping_moments(at, pose, t).moments,
                                   plan.tipping_margins_Nm[i], atol=1e-8)
        np.testing.assert_allclose(wrench_matrix(at, pose) @ t, -gravity_wrench(at, R),
                                   atol=1e-6)
    assert np.all(plan.tipping_margins_Nm >= -TOL_NM)
    assert np.all(plan.final_tipping_margins_Nm >= -TOL_NM)


def test_drive_on_wheels_holds_every_base_upright(robot, drive):
    plan = plan_base_drive(robot, LOW, drive)
    assert plan.success and plan.status == "ok", plan.message
    assert np.isnan(plan.failed_at_s)
    _check_held(plan, LOW)
    assert plan.min_tipping_margin_Nm > 0.0          # strictly upright, not on the edge
    names = [b.name for b in plan.drive_robot.bases]
    active, passive = names.index("active"), names.index("passive")
    assert not plan.drive_robot.bases[active].stabilisers_deployed       # on its wheels
    assert plan.drive_robot.bases[passive].stabilisers_deployed           # parked
    assert all(b.stabilisers_deployed for b in plan.final_robot.bases)    # deployed in place
    np.testing.assert_allclose([b.pose for b in plan.final_robot.bases], drive.poses[-1])


def test_stabilisers_switch_once_and_the_support_polygon_grows(robot, drive):
    plan = plan_base_drive(robot, LOW, drive)
    states = plan.stabilisers_deployed
    assert states.shape == (len(drive.times) + 1, len(robot.bases))
    switches = np.abs(np.diff(states.astype(int), axis=0)).sum(axis=0)
    moved = np.any(drive.poses != drive.poses[:1], axis=(0, 2))
    np.testing.assert_array_equal(switches, moved.astype(int))     # the driver once, others 0
    assert not states[:-1, moved].any() and states[-1].all()       # retracted -> deployed
    for b_drive, b_final in zip(plan.drive_robot.bases, plan.final_robot.bases):
        assert _area(b_final.support_polygon) >= _area(b_drive.support_polygon) - 1e-12
    k = int(np.argmax(moved))
    assert (_area(plan.final_robot.bases[k].support_polygon)
            > 1.5 * _area(plan.drive_robot.bases[k].support_polygon))


def test_a_drive_no_distribution_holds_upright_is_reported(robot, drive):
    plan = plan_base_drive(robot, HIGH, drive)
    assert not plan.success and plan.status == "infeasible"
    assert plan.failed_at_s == drive.times[0] and np.isnan(plan.min_tipping_margin_Nm)
    assert "at t = 0.200 s" in plan.message and "[-3.0, 0.0, 0.0]" in plan.message
    assert "tips a mobile base" in plan.message
    # independent: the LP finds no distribution on the wheels, one with the stabilisers down
    assert not _lp_holds(_robot_at(plan.drive_robot, drive.poses[0]), HIGH)
    assert _lp_holds(robot, HIGH)


def test_a_drive_failing_midway_names_the_first_failing_sample(robot):
    """Driving away from the platform: upright at the start, tipping from some sample on;
    the plan names the first one, and the LP agrees sample by sample."""
    away = BaseMotion.line(robot, "active", (-0.5, 0.0, 0.0), duration=5.0, samples=11)
    pose = [0.3, 0.0, 0.8, 0.0, 0.0, 0.0]
    plan = plan_base_drive(robot, pose, away)
    assert not plan.success
    lp = [_lp_holds(_robot_at(plan.drive_robot, bp), pose) for bp in away.poses]
    first = lp.index(False)
    assert first > 0 and plan.failed_at_s == away.times[first]
    assert f"at t = {away.times[first]:.3f} s" in plan.message
    assert str(np.round(away.poses[first], 4).tolist()) in plan.message
    assert np.all(np.isnan(plan.tensions_N[first]))


@settings(max_examples=12, deadline=None)
@given(x=st.floats(-0.5, 1.0), z=st.floats(0.5, 1.1), dx=st.floats(-0.6, 0.6),
       dtheta=st.floats(-0.3, 0.3))
def test_plan_agrees_with_an_independent_lp(robot, x, z, dx, dtheta):
    """The plan holds iff the LP holds every sample on wheels and the deployed end state
    (up to samples within solver round-off of the tipping boundary)."""
    bm = BaseMotion.line(robot, "active", (dx, 0.0, dtheta), duration=4.0, samples=5)
    pose = [x, 0.0, z, 0.0, 0.0, 0.0]
    plan = plan_base_drive(robot, pose, bm)
    lp = [_lp_holds(_robot_at(plan.drive_robot, bp), pose) for bp in bm.poses]
    lp.append(_lp_holds(plan.final_robot, pose))
    assert plan.success == all(lp), plan.message
    if plan.success:
        _check_held(plan, pose)
    else:
        first = lp.index(False)
        assert plan.failed_at_s == bm.times[min(first, len(bm.times) - 1)]


@pytest.mark.slow  # ~19 s of CPU: the slow target (CI runs it)
def test_simulated_example_drive_keeps_every_tipping_margin_nonnegative(robot, drive):
    """The example's run (velocity law, no model error): every monitored tipping margin of
    every base >= 0 over the whole simulation; the reference tensions are the plan's."""
    plan = plan_base_drive(robot, LOW, drive)
    t = np.linspace(0.0, 5.5, 12)
    ref = reference_from_samples(robot, t, np.tile(LOW, (12, 1)))
    run = simulate(plan.drive_robot, ref, VelocityController(), base_motion=drive)
    assert run.success, run.message
    assert run.tipping_margin.min() >= 0.0
    assert run.base_poses[-1, 0, 0] - run.base_poses[0, 0, 0] == pytest.approx(0.5)
    k = np.searchsorted(run.times, 2.7)
    i = np.searchsorted(drive.times, 2.7)
    np.testing.assert_allclose(run.tensions[k], plan.tensions_N[i], atol=1.0)
    high = reference_from_samples(robot, t, np.tile(HIGH, (12, 1)))
    with pytest.raises(InfeasiblePoseError, match="^base_motion: .*keeps every base upright"):
        simulate(plan.drive_robot, high, VelocityController(), base_motion=drive)


def test_transition_waits_where_the_drive_holds(robot):
    """plan_moving_deployment's drive between stages: the platform waits at the lowest
    face point wrench_feasible holds at every base pose of the drive on wheels; the face
    points plan_base_drive (QP) holds over the same poses are the same ones."""
    a = np.array([-3.35, -0.01, 0.01, 3.37, -0.06, 2.93])
    b = np.array([-1.87, -0.32, 0.35, 3.37, -0.06, 2.93])
    wheels = _stabilisers(robot, [False, True])
    face = grid_points(np.array([[0.0, 0.0, 0.2], [0.0, 0.0, 1.2]]), (1, 1, 11))[0]
    s = np.linspace(0.0, 1.0, 6)
    bm = BaseMotion(s, ((1 - s)[:, None] * a + s[:, None] * b).reshape(6, 2, 3))
    qp = np.array([plan_base_drive(robot, [*p, 0, 0, 0], bm).success for p in face])
    alone = np.array([not np.isnan(_transition_wait(wheels, a, b, face[i:i + 1], 4, None)[0])
                      for i in range(len(face))])
    np.testing.assert_array_equal(qp, alone)
    assert qp.any() and not qp.all()            # the wheels limit the waiting height
    wait = _transition_wait(wheels, a, b, face, 4, None)
    np.testing.assert_array_equal(wait, face[np.argmax(qp)])
    assert np.isnan(_transition_wait(wheels, a, b, face[~qp], 4, None)).all()


def test_units_in_every_field_name():
    """Every numeric field of the drive plan and of a moving deployment's drive says its
    unit (s, m, m_rad, N, Nm); booleans, counts, strings and robots carry none."""
    units = ("_s", "_m", "_m_rad", "_N", "_Nm")
    numeric = [f.name for f in fields(BaseDrivePlan)
               if f.type in ("np.ndarray", "float") and f.name != "stabilisers_deployed"]
    assert len(numeric) == 8
    for name in numeric:
        assert name.endswith(units), name
    assert "transition_wait_m" in {f.name for f in fields(MovingDeploymentResult)}


def test_bad_input(robot, drive):
    with pytest.raises(InvalidInputError, match="^pose"):
        plan_base_drive(robot, [0.3, 0.0, np.nan, 0, 0, 0], drive)
    with pytest.raises(InvalidInputError, match="^base_motion"):
        plan_base_drive(robot, LOW, "drive")
    with pytest.raises(InvalidInputError, match="^robot"):
        plan_base_drive(None, LOW, drive)
    wrong = BaseMotion(drive.times, drive.poses[:, :1])
    with pytest.raises(InvalidInputError, match="^base_motion.poses"):
        plan_base_drive(robot, LOW, wrong)
