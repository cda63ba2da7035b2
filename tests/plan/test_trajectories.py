"""Per-robot trajectories of a plan (issue 28.1): limits, headings, re-verification, files.

The limits are measured here independently of :mod:`taut.plan.execution._timing` (from the
returned times and poses only), and the executed motion is re-verified at a 10x denser
resampling with the public verifier.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from taut.errors import InvalidInputError
from taut.io.robot_trajectories import load_robot_trajectories, save_robot_trajectories
from taut.plan import resample_motion, robot_trajectories, verify_motion
from taut.plan.execution._drives import drive_path
from taut.plan.execution._timing import time_path

LIMITS = dict(max_speed=0.2, max_accel=0.5, max_yaw_rate=1.0)
RTOL = 1e-9


def measure(times, poses):
    """Largest robot speed, acceleration (velocity change over the mean duration of the
    two intervals, from and to rest), yaw rate and yaw acceleration (the same definition),
    from the samples alone."""
    dt = np.diff(times)
    assert np.all(dt > 0)
    v = np.diff(poses[..., :2], axis=0) / dt[:, None, None]
    yaw = np.abs(np.diff(poses[..., 2], axis=0)) / dt[:, None]
    vel = np.concatenate([np.zeros((1, *v.shape[1:])), v, np.zeros((1, *v.shape[1:]))])
    mid = np.concatenate([[0.0], dt, [0.0]])
    mid = (mid[:-1] + mid[1:]) / 2
    acc = np.linalg.norm(np.diff(vel, axis=0), axis=2) / mid[:, None]
    om = np.diff(poses[..., 2], axis=0) / dt[:, None]
    om = np.concatenate([np.zeros((1, om.shape[1])), om, np.zeros((1, om.shape[1]))])
    yaw_acc = np.abs(np.diff(om, axis=0)) / mid[:, None]
    return np.linalg.norm(v, axis=2).max(), acc.max(), yaw.max(), yaw_acc.max()


def violations(tr, limits=LIMITS, yaw_accel=2.0):
    speed, acc, yaw, yaw_acc = measure(tr.times, tr.poses)
    return [name for name, got, lim in (("speed", speed, limits["max_speed"]),
                                        ("accel", acc, limits["max_accel"]),
                                        ("yaw", yaw, limits["max_yaw_rate"]),
                                        ("yaw_accel", yaw_acc, yaw_accel))
            if got > lim * (1 + RTOL)]


def reverify_10x(sc, result, tr):
    robots, obj = resample_motion(tr.poses[..., :2], tr.object, 10)
    return verify_motion(sc, robots, obj, sheet_margin=result.sheet_margin)


@pytest.fixture(scope="module")
def executed(paper_corridor_plan):
    _, result = paper_corridor_plan
    return {d: robot_trajectories(result, drive=d, **LIMITS)
            for d in ("holonomic", "differential")}


@pytest.mark.parametrize("drive", ["holonomic", "differential"])
def test_limits_hold_and_the_executed_motion_reverifies_at_10x(paper_corridor_plan, executed,
                                                                drive):
    sc, result = paper_corridor_plan
    tr = executed[drive]
    assert tr.success and tr.status == "ok", tr.message
    assert violations(tr) == []
    T, N = len(tr.times), sc.team.n
    assert tr.poses.shape == (T, N, 3) and tr.object.shape == (T, 3)
    assert tr.times[0] == 0 and tr.duration == tr.times[-1]
    check = reverify_10x(sc, result, tr)
    assert check.success, check.message
    # every robot goes where the plan goes: start and goal positions are the plan's
    np.testing.assert_allclose(tr.poses[0, :, :2], result.robots[0])
    np.testing.assert_allclose(tr.poses[-1, :, :2], result.robots[-1])
    # the object from FK along the trajectories is the plan's object where both are
    np.testing.assert_allclose(tr.object[[0, -1]], result.object[[0, -1]], atol=1e-6)


def test_differential_heading_is_the_direction_of_motion(executed):
    tr = executed["differential"]
    step = np.diff(tr.poses[..., :2], axis=0)
    moving = np.linalg.norm(step, axis=2) > 1e-6
    direction = np.arctan2(step[..., 1], step[..., 0])
    off = np.angle(np.exp(1j * (tr.poses[:-1, :, 2] - direction)))
    assert moving.any()
    assert np.abs(off[moving]).max() < 1e-9
    # turns in place: no robot moves, and they take time
    still = ~moving.any(axis=1)
    assert still.sum() == tr.turns > 0
    assert np.all(np.diff(tr.times)[still] > 0)


def test_holonomic_robots_turn_with_the_formation(paper_corridor_plan, executed):
    _, result = paper_corridor_plan
    tr = executed["holonomic"]
    assert tr.turns == 0
    assert np.ptp(tr.poses[..., 2], axis=1).max() < 1e-12          # one heading for all
    np.testing.assert_allclose(tr.poses[[0, -1], 0, 2],
                               np.unwrap(result.heading)[[0, -1]], atol=1e-12)
    # a differential drive that must turn in place is never faster
    assert executed["differential"].duration >= tr.duration


def test_tighter_limits_take_longer_and_are_respected(paper_corridor_plan):
    _, result = paper_corridor_plan
    slow = dict(max_speed=0.05, max_accel=0.1, max_yaw_rate=0.3)
    tr = robot_trajectories(result, drive="differential", **slow)
    assert tr.success and violations(tr, slow) == []
    fast = robot_trajectories(result, drive="differential", **LIMITS)
    assert tr.duration > fast.duration
    # the default yaw acceleration limit (2 rad/s^2) binds on the turns in place
    turn = robot_trajectories(result, drive="differential", max_yaw_accel=0.2, **LIMITS)
    assert turn.success and violations(turn, yaw_accel=0.2) == []
    assert turn.duration > fast.duration and turn.peak_yaw_accel <= 0.2 * (1 + RTOL)
    assert fast.peak_yaw_accel <= 2.0 * (1 + RTOL) and fast.max_yaw_accel == 2.0


@pytest.mark.parametrize("suffix", [".csv", ".json"])
def test_files_round_trip_exactly(executed, tmp_path, suffix):
    tr = executed["differential"]
    path = tmp_path / f"traj{suffix}"
    save_robot_trajectories(path, tr)
    back = load_robot_trajectories(path)
    np.testing.assert_array_equal(back.times, tr.times)
    np.testing.assert_array_equal(back.poses, tr.poses)
    np.testing.assert_array_equal(back.object, tr.object)


def test_bad_options_are_typed_errors(paper_corridor_plan):
    _, result = paper_corridor_plan
    with pytest.raises(InvalidInputError, match="drive"):
        robot_trajectories(result, drive="tank", **LIMITS)
    with pytest.raises(InvalidInputError, match="max_accel"):
        robot_trajectories(result, max_speed=0.2, max_accel=-1.0, max_yaw_rate=1.0)
    with pytest.raises(InvalidInputError, match="result"):
        robot_trajectories(None, **LIMITS)                       # type: ignore[arg-type]


def _paths(draw_n=st.integers(2, 5)):
    """Random robot polylines (T, N, 2) with random formation-change flags."""
    return st.tuples(draw_n, st.integers(3, 25), st.integers(0, 2**32 - 1))


@settings(max_examples=40, deadline=None)
@given(_paths(), st.sampled_from(["holonomic", "differential"]),
       st.floats(0.05, 2.0), st.floats(0.05, 3.0), st.floats(0.1, 5.0), st.floats(0.05, 5.0))
def test_timing_respects_every_limit_on_random_paths(shape, drive, vmax, amax, wmax, alpha):
    n, T, seed = shape
    rng = np.random.default_rng(seed)
    robots = np.cumsum(rng.normal(0, 0.02, (T, n, 2)), axis=0)
    heading = np.cumsum(rng.normal(0, 0.05, T))
    reform = rng.random(T - 1) < 0.3
    path = drive_path(robots, heading, np.zeros((T, 3)), reform, drive)
    times = time_path(path.robots, path.heading, path.reform, max_speed=vmax,
                      max_accel=amax, max_yaw_rate=wmax, reform_speed=0.05,
                      max_yaw_accel=alpha)
    poses = np.concatenate([path.robots, path.heading[..., None]], axis=2)
    speed, acc, yaw, yaw_acc = measure(times, poses)
    assert speed <= vmax * (1 + RTOL) and acc <= amax * (1 + RTOL) and yaw <= wmax * (1 + RTOL)
    assert yaw_acc <= alpha * (1 + RTOL)
    step = np.linalg.norm(np.diff(path.robots, axis=0), axis=2).max(axis=1)
    v = step / np.diff(times)
    assert np.all(v[path.reform] <= 0.05 * (1 + RTOL))            # quasi-static changes
    np.testing.assert_array_equal(path.robots[[0, -1]], robots[[0, -1]])


def test_cli_writes_the_trajectories_the_library_gives(paper_corridor_plan, executed,
                                                       tmp_path, capsys):
    from taut.cli import main
    from .conftest import EXAMPLES
    out = tmp_path / "t.csv"
    code = main(["plan", str(EXAMPLES / "paper_corridor.yaml"), "--drive", "differential",
                 "--trajectories", str(out), "--max-speed", "0.2", "--max-accel",
                 "0.5", "--max-yaw-rate", "1"])
    assert code == 0
    back = load_robot_trajectories(out)
    np.testing.assert_array_equal(back.poses, executed["differential"].poses)
    capsys.readouterr()
    code = main(["plan", str(EXAMPLES / "paper_corridor.yaml"), "--trajectories", str(out),
                 "--max-speed", "0.2"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--max-accel" in err[0]
    code = main(["plan", str(EXAMPLES / "paper_corridor.yaml"), "--trajectories", str(out),
                 "--max-speed", "0.2", "--max-accel", "0.5", "--max-yaw-rate", "1",
                 "--max-yaw-accel", "-1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--max-yaw-accel" in err[0]
