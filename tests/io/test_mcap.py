"""ROS 2 recordings: every file is read back with rosbags (an independent, pure-Python ROS 2
decoder with its own CDR implementation and typestore) and its numbers compared with the
result's arrays."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")
rosbags = pytest.importorskip("rosbags")

from rosbags.highlevel import AnyReader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from taut.cli import main  # noqa: E402
from taut.errors import InvalidInputError  # noqa: E402
from taut.io import load_plan_scenario, load_sheet_scenario, plan_scenario_from_mapping  # noqa: E402
from taut.io import write_mcap  # noqa: E402
from taut.io._recording import quaternion_from_rpy  # noqa: E402
from taut.io.mcap import TOPICS  # noqa: E402
from taut.sheet import forward_kinematics, simulate  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SHEET = ROOT / "examples" / "sheet"


def read(path: Path) -> dict[str, list[tuple[int, object]]]:
    """topic -> [(log time ns, decoded message)], and every connection's type checked
    against the documented one."""
    out: dict[str, list[tuple[int, object]]] = defaultdict(list)
    store = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([path], default_typestore=store) as reader:
        for c in reader.connections:
            generic = c.topic.replace(c.topic.split("/")[2], "robot_<i>") \
                if c.topic.startswith("/taut/robot_") else c.topic
            assert TOPICS[generic] == c.msgtype, c.topic
        for c, t, raw in reader.messages():
            out[c.topic].append((t, reader.deserialize(raw, c.msgtype)))
    return out


def xyz(p) -> np.ndarray:
    return np.array([p.x, p.y, p.z])


def quat(q) -> np.ndarray:
    return np.array([q.x, q.y, q.z, q.w])


def test_quaternions_rotate_like_the_rotation_matrices():
    from taut.cdpr import rotation_matrices
    rpy = np.random.default_rng(3).uniform(-3, 3, (20, 3))
    q = quaternion_from_rpy(rpy)
    x, y, z, w = q.T
    R = np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                  np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                  np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)],
                 axis=1)
    assert np.allclose(R, rotation_matrices(rpy), atol=1e-12)


def test_fk_recording_reads_back_in_metres(tmp_path):
    sc = load_sheet_scenario(SHEET / "example1.yaml")            # units: mm, mass 1 kg
    r = forward_kinematics(sc.team, sc.formation)
    e = r.lowest
    out = write_mcap(r, tmp_path / "fk.mcap", length_unit=sc.units)
    msgs = read(out)
    (t, pose), = msgs["/taut/object/pose"]
    assert t == 0 and pose.header.frame_id == "world"
    assert np.allclose(xyz(pose.pose.position), e.object * 1e-3, rtol=0, atol=1e-12)
    assert np.allclose(quat(pose.pose.orientation), [0, 0, 0, 1])
    for i, xy in enumerate(sc.formation):
        (_, p), = msgs[f"/taut/robot_{i + 1}/pose"]
        assert np.allclose(xyz(p.pose.position), [*(xy * 1e-3), 0.0], atol=1e-12)
    (_, js), = msgs["/taut/cables"]
    assert list(js.name) == [f"cable_{i + 1}" for i in range(sc.team.n)]
    tensions = np.zeros(sc.team.n)
    tensions[list(e.taut)] = e.tensions
    assert np.allclose(js.effort, tensions, atol=1e-12)
    # a taut cable's straight length from its held corner is its sheet distance l_i
    assert np.allclose(js.position[list(e.taut)], e.cable_lengths * 1e-3, atol=1e-9)
    (_, tf), = msgs["/tf"]
    frames = {x.child_frame_id: xyz(x.transform.translation) for x in tf.transforms}
    assert np.allclose(frames["object"], e.object * 1e-3)
    assert set(frames) == {"object"} | {f"robot_{i + 1}" for i in range(sc.team.n)}
    markers = [m for _, a in msgs["/taut/markers"] for m in a.markers]
    stable = [m for m in markers if m.ns == "equilibria/stable"][0]
    assert len(stable.points) == len(r.stable)
    cables = [m for m in markers if m.ns == "cables"][0]
    assert len(cables.points) == 2 * len(e.taut)


def test_simulation_recording_has_every_step(tmp_path):
    sc = load_sheet_scenario(SHEET / "trajectories" / "square4.yaml")
    from taut.io.trajectory import load_trajectory
    traj = load_trajectory(SHEET / "trajectories" / "square4_jump.csv")
    sim = simulate(sc.team, traj.formations)
    times = traj.time
    out = write_mcap(sim, tmp_path / "sim.mcap", length_unit=sc.units, times=times)
    scale = {"m": 1.0, "mm": 1e-3}[sc.units]
    msgs = read(out)
    stamps = np.array([t for t, _ in msgs["/taut/object/pose"]]) * 1e-9
    ok = np.all(np.isfinite(sim.object), axis=1)
    assert np.allclose(stamps, times[ok], atol=1e-9)
    got = np.array([xyz(m.pose.position) for _, m in msgs["/taut/object/pose"]])
    assert np.allclose(got, sim.object[ok] * scale, atol=1e-12)
    js = [m for _, m in msgs["/taut/cables"]]
    assert len(js) == len(times)
    assert np.allclose([m.effort for m in js], sim.tensions, atol=1e-12)
    sec = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in js])
    assert np.allclose(sec, times, atol=1e-9)
    speed = np.array([m.velocity for m in js])
    length = np.array([m.position for m in js])
    assert np.allclose(speed, np.gradient(length, times, axis=0))
    assert len(sim.jumps) == 1                               # the recording holds a jump


def test_control_recording_has_the_platform_wrench(tmp_path):
    from taut.cdpr import (TorqueController, distribute_tensions, reference_from_samples,
                           simulate as cdpr_simulate, with_stabilisers)
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    pose = np.array([0.3, 0.0, 1.0, 0.0, 0.0, 0.2])
    t = np.linspace(0.0, 0.05, 11)
    run = cdpr_simulate(robot, reference_from_samples(robot, t, np.tile(pose, (11, 1))),
                        TorqueController(), backend="numpy", control_rate=200.0)
    out = write_mcap(run, tmp_path / "cdpr.mcap", robot=robot)
    msgs = read(out)
    got = np.array([xyz(m.pose.position) for _, m in msgs["/taut/object/pose"]])
    assert np.allclose(got, run.poses[:, :3], atol=1e-12)
    q = np.array([quat(m.pose.orientation) for _, m in msgs["/taut/object/pose"]])
    assert np.allclose(q, quaternion_from_rpy(run.poses[:, 3:]), atol=1e-12)
    js = [m for _, m in msgs["/taut/cables"]]
    assert np.allclose([m.effort for m in js], run.tensions, atol=1e-12)
    assert list(js[0].name) == list(run.cable_names)
    # the recorded wrench balances the platform's weight at rest (cross-check of W @ t)
    w = np.array([[*xyz(m.wrench.force), *xyz(m.wrench.torque)]
                  for _, m in msgs["/taut/platform/wrench"]])
    weight = robot.total_mass * 9.81
    assert np.allclose(w[:, 2], weight, rtol=2e-3)
    assert np.abs(w[:, :2]).max() < 2e-3 * weight
    # bases are the robots, on the ground, with their yaw
    for i in range(run.base_poses.shape[1]):
        p = [m for _, m in msgs[f"/taut/robot_{i + 1}/pose"]][0]
        x, y, th = run.base_poses[0, i]
        assert np.allclose(xyz(p.pose.position), [x, y, 0.0])
        assert np.isclose(2 * np.arctan2(p.pose.orientation.z, p.pose.orientation.w), th)


SMALL_PLAN = {
    "units": "m", "free_space": [[0, -1], [3, -1], [3, 1], [0, 1]], "obstacles": [],
    "start": [0.8, 0.0], "goal": [1.6, 0.0],
    "team": {"regular": {"n": 3, "circumradius": 0.5773502691896258}, "hold_height": 0.5,
             "robot_radius": 0.15, "height_safety": 0.05, "lateral_safety": 0.05,
             "speed": 0.1, "rotation_speed": 0.3, "mass": 0.17}}


@pytest.fixture(scope="module")
def small_plan():
    from taut.plan import plan
    sc = plan_scenario_from_mapping(SMALL_PLAN)
    r = plan(sc)
    assert r.success, r.message
    return r


def test_plan_recording_has_paths(tmp_path, small_plan):
    r = small_plan
    msgs = read(write_mcap(r, tmp_path / "plan.mcap"))
    for i in range(r.robots.shape[1]):
        (t, path), = msgs[f"/taut/robot_{i + 1}/path"]
        pts = np.array([xyz(p.pose.position) for p in path.poses])
        assert np.allclose(pts[:, :2], r.robots[:, i], atol=1e-12)
        yaw = [2 * np.arctan2(p.pose.orientation.z, p.pose.orientation.w) for p in path.poses]
        assert np.allclose(np.unwrap(yaw), np.unwrap(r.heading), atol=1e-9)
        assert len(msgs[f"/taut/robot_{i + 1}/pose"]) == len(r.times)
    got = np.array([xyz(m.pose.position) for _, m in msgs["/taut/object/pose"]])
    assert np.allclose(got, r.object, atol=1e-12)
    assert "/taut/platform/wrench" not in msgs


def test_trajectories_recording_has_each_robots_heading(tmp_path, small_plan):
    from taut.plan import robot_trajectories
    tr = robot_trajectories(small_plan, drive="differential", max_speed=0.2, max_accel=0.5,
                            max_yaw_rate=1.0)
    assert tr.success, tr.message
    msgs = read(write_mcap(tr, tmp_path / "tr.mcap", plan=small_plan))
    for i in range(tr.poses.shape[1]):
        got = [m for _, m in msgs[f"/taut/robot_{i + 1}/pose"]]
        assert np.allclose([xyz(m.pose.position)[:2] for m in got], tr.poses[:, i, :2])
        yaw = np.unwrap([2 * np.arctan2(m.pose.orientation.z, m.pose.orientation.w)
                         for m in got])
        assert np.allclose(yaw - yaw[0], tr.poses[:, i, 2] - tr.poses[0, i, 2], atol=1e-9)
        assert np.isclose(np.cos(yaw[0] - tr.poses[0, i, 2]), 1.0)
    with pytest.raises(InvalidInputError, match="plan"):
        write_mcap(tr, tmp_path / "x.mcap")


def test_cli_plan_and_physics(tmp_path, capsys):
    import yaml
    scenario = tmp_path / "small.yaml"
    scenario.write_text(yaml.safe_dump(SMALL_PLAN))
    assert main(["plan", str(scenario), "--mcap", str(tmp_path / "p.mcap"), "--json"]) == 0
    msgs = read(tmp_path / "p.mcap")
    assert {f"/taut/robot_{i}/path" for i in (1, 2, 3)} <= set(msgs)


@pytest.mark.slow
def test_physics_check_recording(tmp_path, capsys):
    pytest.importorskip("mujoco")
    from taut.physics import replay_equilibria
    sc = load_sheet_scenario(SHEET / "example1.yaml")
    out = tmp_path / "ph.mcap"
    assert main(["physics", str(SHEET / "example1.yaml"), "--mcap", str(out)]) in (0, 1)
    msgs = read(out)
    check = replay_equilibria(sc.team, sc.formation)
    got = np.array([xyz(m.pose.position) for _, m in msgs["/taut/object/pose"]])
    settled = np.array([s.settled for s in check.states])
    ok = np.all(np.isfinite(settled), axis=1)
    assert np.allclose(got, settled[ok] * 1e-3, atol=1e-6)     # MuJoCo is deterministic
    sheet = [m for _, a in msgs["/taut/markers"] for m in a.markers if m.ns == "sheet"]
    assert len(sheet) == len(check.states)


def test_mission_track_recording(tmp_path):
    mission = pytest.importorskip("taut.cdpr.mission.mission")
    t = np.linspace(0.0, 2.0, 9)
    bases = np.column_stack([0.1 * t, np.zeros_like(t), 0.3 * t])
    platform = np.column_stack([0.1 * t, np.zeros_like(t), 1.0 + 0.1 * t])
    r = mission.MissionResult(True, "ok", "synthetic track", (), 2.0, 2.0, 2.0, 2.0, (), (),
                              (), (), t, bases, platform)
    msgs = read(write_mcap(r, tmp_path / "mission.mcap"))
    got = np.array([xyz(m.pose.position) for _, m in msgs["/taut/object/pose"]])
    assert np.allclose(got, platform)
    (_, path), = msgs["/taut/robot_1/path"]
    yaw = [2 * np.arctan2(p.pose.orientation.z, p.pose.orientation.w) for p in path.poses]
    assert np.allclose(yaw, bases[:, 2])


def test_context_is_checked(tmp_path):
    sc = load_sheet_scenario(SHEET / "example1.yaml")
    r = forward_kinematics(sc.team, sc.formation)
    with pytest.raises(InvalidInputError, match="length_unit"):
        write_mcap(r, tmp_path / "a.mcap")
    with pytest.raises(InvalidInputError, match="length_unit"):
        write_mcap(r, tmp_path / "a.mcap", length_unit="furlong")
    with pytest.raises(InvalidInputError, match="times"):
        write_mcap(r, tmp_path / "a.mcap", length_unit="mm", times=[0.0])
    with pytest.raises(InvalidInputError, match="cannot record a dict"):
        write_mcap({}, tmp_path / "a.mcap")
    assert not (tmp_path / "a.mcap").exists()


def test_cli_writes_both_and_refuses_bad_outputs(tmp_path, capsys, monkeypatch):
    scenario = tmp_path / "sc.yaml"
    scenario.write_text((SHEET / "example1.yaml").read_text())
    assert main(["fk", str(scenario), "--mcap", str(tmp_path / "o.mcap")]) == 0
    assert read(tmp_path / "o.mcap")["/taut/object/pose"]
    capsys.readouterr()
    # an output that is an input (another spelling of the scenario) is refused before work
    twin = tmp_path / "sc.mcap"
    twin.hardlink_to(scenario)
    assert main(["simulate", str(scenario), "--trajectory", str(twin), "--mcap",
                 str(twin)]) == 2
    assert "--mcap" in capsys.readouterr().err
    assert main(["fk", str(scenario), "--rerun", str(tmp_path / "o.mcap")]) == 2
    assert "--rerun: unsupported extension" in capsys.readouterr().err
    # a scenario without units: cannot be recorded in metres
    bare = tmp_path / "bare.yaml"
    bare.write_text("\n".join(line for line in scenario.read_text().splitlines()
                              if not line.startswith("units:")))
    assert main(["fk", str(bare), "--mcap", str(tmp_path / "b.mcap")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "units" in err
    # the extra missing: one line naming it, exit 2, nothing computed
    monkeypatch.setitem(__import__("sys").modules, "mcap_ros2.writer", None)
    assert main(["fk", str(scenario), "--mcap", str(tmp_path / "c.mcap")]) == 2
    err = capsys.readouterr().err
    assert err == "taut: error: --mcap: needs the mcap extra: pip install 'taut[mcap]'\n"
    assert not (tmp_path / "c.mcap").exists()
