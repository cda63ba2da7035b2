"""The mission (taut.cdpr.mission.mission and .execute): phase bookkeeping against the
baseline, monitors re-checked independently along a simulated run, and the example end to
end (slow)."""

from pathlib import Path

import numpy as np
import pytest

import taut.cdpr.mission.mission as mission_mod
from taut.cdpr import (NavigationResult, PHASE_KINDS, Site, SitesResult, TorqueController,
                       UnservedTask, plan_mission, simulate, time_optimal_path,
                       tipping_moments, to_robot_frame, with_box, with_friction,
                       with_stabilisers)
from taut.cdpr.mission._execute import run_motion
from taut.io import load_warehouse

EXAMPLE = Path(__file__).parents[3] / "examples" / "cdpr" / "warehouse.yaml"


@pytest.fixture(scope="module")
def warehouse():
    return load_warehouse(EXAMPLE)


def _fake_sites(wh):
    """One hand-placed site in front of rack A serving box1 and box2; box8 unserved."""
    robot = with_stabilisers(with_friction(wh.robot, wh.friction))
    pose = np.array([10.0, 10.05, 0.0])
    tasks = [t for t in wh.tasks if t.name in ("box1", "box2")]
    pk = to_robot_frame(pose, np.array([t.pick for t in tasks]))
    pl = to_robot_frame(pose, np.array([t.place for t in tasks]))
    pk[:, 1] = pl[:, 1] = 0.0
    site = Site(pose, robot, True, np.zeros((2, 3)), ("box1", "box2"), pk, pl, 1.0, "A")
    return SitesResult(False, "unreachable", "box8 out of reach", (site,),
                       (UnservedTask("box8", "out of reach"),))


#: Duration of the fake route, s.
NAV_S = 120.0


def _fake_route(wh, start, goal, **_):
    """Round the racks' east ends (x = 19.5 m, clear of every shelf), each leg rest to rest
    on a smooth cubic, NAV_S s in all."""
    corners = np.array([start, [19.5, start[1], 0.0], [19.5, goal[1], 0.0], goal], float)
    leg = NAV_S / 3
    s = np.linspace(0.0, 1.0, 101)[:-1]
    smooth = 3 * s ** 2 - 2 * s ** 3
    poses = np.vstack([a + smooth[:, None] * (b - a) for a, b in zip(corners, corners[1:])]
                      + [corners[-1:]])
    t = np.linspace(0.0, NAV_S, len(poses))
    return NavigationResult(True, "ok", "round the racks", t, poses, NAV_S)


def test_phases_tile_the_mission_and_beat_the_baseline(warehouse, monkeypatch):
    monkeypatch.setattr(mission_mod, "choose_sites", lambda wh, step: _fake_sites(wh))
    monkeypatch.setattr(mission_mod, "plan_navigation", _fake_route)
    seen = []
    res = plan_mission(warehouse, simulate_runs=False, progress=lambda d, n: seen.append(d))
    kinds = [p.kind for p in res.phases]
    assert kinds == ["navigate", "deploy"] + ["pick", "carry", "place"] * 2 + ["retract"]
    assert set(kinds) <= set(PHASE_KINDS)
    ends = np.array([(p.start, p.end) for p in res.phases])
    assert ends[0, 0] == 0 and np.allclose(ends[1:, 0], ends[:-1, 1])
    assert res.total_time == pytest.approx(ends[-1, 1])
    # fixed times (route, 3 s + 3 s stabilisers, 4 x 0.5 s gripper) are in both totals
    fixed = NAV_S + 2 * mission_mod.STABILISER_S + 4 * mission_mod.GRIP_S
    assert res.total_time == pytest.approx(fixed + res.motion_time)
    assert res.baseline_total_time == pytest.approx(fixed + res.baseline_motion_time)
    assert res.total_time < res.baseline_total_time
    assert res.served == ("box1", "box2") and res.unserved[0].name == "box8"
    assert "box8" in res.message and res.success and res.status == "ok"
    assert seen == sorted(seen) and seen[-1] == len(seen)
    assert res.track_times.shape[0] == res.track_bases.shape[0] == res.track_platform.shape[0]
    assert np.all(np.diff(res.track_times) >= -1e-9)


def test_monitors_rechecked_along_a_simulated_run(warehouse):
    robot = with_box(with_stabilisers(with_friction(warehouse.robot, warehouse.friction)), 4.0)
    pose = np.array([10.0, 10.05, 0.0])
    law = time_optimal_path(robot, [[-1.4, 0, 0.6], [-1.4, 0, 0.7], [-1.2, 0, 1.0]])
    mon = run_motion(warehouse, pose, robot, law, mission_mod.DynamicsModel())
    run = simulate(robot, law.reference(), TorqueController())       # deterministic
    T = run.tensions
    # tension limits re-checked from the recorded tensions
    assert mon.min_tension_margin == pytest.approx(
        np.minimum(T - robot.t_min, robot.t_max - T).min())
    assert mon.min_tension_margin >= 0
    # tipping re-checked by the statics (eqs. 21-23) at the recorded poses and tensions
    sel = slice(None, None, 25)
    tip = tipping_moments(robot, run.poses[sel], T[sel])
    assert tip.stable.all()
    assert mon.min_tipping_margin == pytest.approx(-tip.moments.max(), abs=5.0)
    assert mon.min_tipping_margin <= -tip.moments.max() + 1e-6
    assert mon.success and mon.min_sliding_margin >= 0 and mon.min_clearance > 0


@pytest.mark.slow
def test_example_mission_end_to_end(warehouse):
    res = plan_mission(warehouse)
    assert res.success, res.message
    assert {u.name for u in res.unserved} == {"box8"}
    assert set(res.served) == {f"box{k}" for k in range(1, 8)}
    assert len(res.sites) >= 2
    for p in res.phases:
        assert p.min_tension_margin >= 0 and p.min_tipping_margin >= 0, p
        assert p.min_sliding_margin >= 0, p
    assert res.total_time < res.baseline_total_time


def test_an_active_base_move_costs_its_stabilisers_and_drive(warehouse):
    assert mission_mod.drive_time(0.0, 0.25, 3.0) == 0.0
    # 0.6 m at 0.2 m/s and 0.25 m/s^2: 0.8 s ramps, 3 s cruise => 3.8 s, plus 2 x 3 s
    assert mission_mod.drive_time(0.6, 0.25, 3.0) == pytest.approx(9.8)
    robot = warehouse.robot
    moved = mission_mod.shifted(robot, 0.5)
    k = mission_mod.active_index(robot)
    assert np.allclose(moved.bases[k].pose, robot.bases[k].pose + [0.5, 0, 0])
    assert np.allclose(moved.bases[1 - k].pose, robot.bases[1 - k].pose)


@pytest.mark.slow
def test_active_base_moves_when_it_pays_and_is_monitored(warehouse, monkeypatch):
    monkeypatch.setattr(mission_mod, "choose_sites", lambda wh, step: _fake_sites(wh))
    monkeypatch.setattr(mission_mod, "plan_navigation", _fake_route)
    still = plan_mission(warehouse, simulate_runs=False)
    # with the real move cost (>= 6 s of stabilisers) the base stays put
    kept = plan_mission(warehouse, simulate_runs=False, active_base_offsets=[-0.6, 0.6])
    assert [r.offset for r in kept.repositions] == [0.0, 0.0]
    assert kept.total_time == pytest.approx(still.total_time)
    # free moves: it moves whenever that is faster, and the totals add up
    monkeypatch.setattr(mission_mod, "drive_time", lambda d, a, s: 0.0)
    moved = plan_mission(warehouse, simulate_runs=False, active_base_offsets=[-0.6, 0.6])
    assert any(r.offset != 0.0 for r in moved.repositions)
    assert moved.motion_time <= still.motion_time + 1e-9
    assert moved.success, moved.message
    for r in moved.repositions:
        assert r.saved <= 1e-9 and r.best_saving >= -r.saved - 1e-9
