"""Motion planning with obstacle crossing (issue 4): the roadmap planners, models, files, CLI."""

import json
from pathlib import Path

import numpy as np
import pytest
import typer

from taut.errors import InvalidInputError, PlanningError, ScenarioError
from taut.io.plan_scenario import (load_plan_scenario, plan_scenario_from_mapping,
                                   plan_scenario_to_mapping)
from taut.plan import (Obstacle, Scenario, Team, World, crossing_pairs, generate_scenario,
                       offset_crossings, optimal_formation, plan, verify_motion)
from taut.sheet import Sheet, SheetTeam, forward_kinematics

EXAMPLES = Path(__file__).parents[2] / "examples" / "plan"


def corridor_team(hold_height=0.5, **kw):
    args = dict(robot_radius=0.15, height_safety=0.05, lateral_safety=0.05, speed=0.1,
                rotation_speed=0.3)
    args.update(kw)
    return Team(SheetTeam(Sheet.regular(3, 1 / np.sqrt(3)), hold_height), **args)


def corridor(obstacles, width=2.0, length=6.0, team=None):
    w = width / 2
    world = World([[0, -w], [length, -w], [length, w], [0, w]], tuple(obstacles))
    return Scenario(world, team or corridor_team(), [0.8, 0.0], [length - 0.8, 0.0])


@pytest.fixture(scope="module")
def paper():
    return load_plan_scenario(EXAMPLES / "paper_corridor.yaml")


@pytest.fixture(scope="module")
def paper_plan(paper):
    """The disc-model roadmap with straight offset crossings (issue 4's planner)."""
    return plan(paper, method="roadmap")


@pytest.fixture(scope="module")
def paper_alg2(paper):
    """The paper's Algorithm 2 only (every crossed obstacle passes under the object)."""
    return plan(paper, method="algorithm2")


def test_paper_corridor_straight_crossings(paper, paper_plan, paper_alg2):
    r = paper_plan
    assert r.success and set(r.crossed) == {"1", "2"}
    assert r.duration < paper_alg2.duration               # no turn at the obstacles
    assert all(c.turn == 0.0 and c.kind == "straight" for c in r.crossings)
    # Each obstacle passes under the sheet between two robots, clear of them.
    for c in r.crossings:
        o = paper.world.obstacle(c.obstacle)
        sel = (r.times >= c.times[0]) & (r.times <= c.times[4])
        d = np.linalg.norm(r.robots[sel] - o.mec_center, axis=2)
        assert d.min() >= o.mec_radius + paper.team.clearance - 1e-9
    assert verify_motion(paper, r.robots, r.object).success


def test_paper_corridor_must_cross(paper, paper_alg2):
    r = paper_alg2
    assert r.success and r.status == "ok"
    assert set(r.crossed) == {"1", "2"} and r.bypassed == ()
    assert np.allclose(r.object[0, :2], paper.start) and np.allclose(r.object[-1, :2], paper.goal)
    # Both obstacles pass under the object, with the height safety.
    for oid, x in (("1", 2.0), ("2", 4.0)):
        o = paper.world.obstacle(oid)
        near = np.linalg.norm(r.object[:, :2] - [x, 0.0], axis=1) < 1e-9
        assert near.any()
        assert np.all(r.object[near, 2] >= o.height + paper.team.height_safety - 1e-9)
    # Times increase, speeds are the team's.
    dt = np.diff(r.times)
    assert np.all(dt > 0)
    step = np.linalg.norm(np.diff(r.object[:, :2], axis=0), axis=1)
    moving = step > 1e-12
    assert np.allclose(step[moving] / dt[moving], paper.team.speed)
    assert r.duration == pytest.approx(r.times[-1])
    # Algorithm 2 on a triangle: the turn at the obstacle is 60 degrees.
    assert all(abs(abs(c.turn) - np.pi / 3) < 1e-6 for c in r.crossings)
    # Every cable taut at every sample.
    assert all(len(s) == 3 for s in r.taut)


def test_paper_corridor_disc_baseline_fails_with_reason(paper):
    b = plan(paper, baseline="disc")
    assert not b.success and b.status == "no_route" and b.planner == "disc"
    assert "cannot pass" in b.message
    assert b.robots.shape == (0, 3, 2)
    assert not hasattr(b, "reason")                     # one name: message


def test_returned_plan_passes_independent_verification(paper, paper_plan):
    r = paper_plan
    check = verify_motion(paper, r.robots, r.object)
    assert check.success, check.message
    assert check.min_height_margin >= paper.team.height_safety - 1e-9
    assert check.min_clearance >= paper.team.clearance - 1e-9
    # FK on a sample mid-crossing finds the planned object as a stable all-taut state.
    t = int(np.argmin(np.linalg.norm(r.object[:, :2] - [4.0, 0.0], axis=1)))
    fk = forward_kinematics(paper.team.carrier, r.robots[t])
    assert any(len(e.taut) == 3 and np.allclose(e.object, r.object[t], atol=1e-9)
               for e in fk.stable)


def test_verification_rejects_bad_motions(paper, paper_plan):
    r = paper_plan
    lowered = r.object.copy()
    lowered[:, 2] -= 0.01
    assert "planned branch" in verify_motion(paper, r.robots, lowered).message
    shifted = r.robots + [0.0, 0.3]                     # into the wall
    bad = verify_motion(paper, shifted, r.object + [0.0, 0.3, 0.0])
    assert not bad.success and bad.status == "refuted"
    assert "wall" in bad.message or "free space" in bad.message
    # Same motion, but obstacle 2 too tall: the object would scrape it.
    tall = Scenario(World(paper.world.free_space, (
        paper.world.obstacles[0], Obstacle("2", 0.23, center=[4.0, 0.0], radius=0.15))),
        paper.team, paper.start, paper.goal)
    res = verify_motion(tall, r.robots, r.object)
    assert not res.success and "above obstacle '2'" in res.message


def test_must_bypass_tall_obstacle():
    # Wide hall: the tall box cannot be crossed but there is room beside it.
    sc = corridor([Obstacle("tall", 0.8, center=[3.0, 0.0], radius=0.2)], width=4.0)
    r = plan(sc, time_budget=600)
    assert r.success and r.crossed == () and r.bypassed == ("tall",)
    assert verify_motion(sc, r.robots, r.object).success
    d = np.linalg.norm(r.robots - [3.0, 0.0], axis=2)
    assert d.min() >= 0.2 + sc.team.clearance - 1e-6
    # Straight-line distance would be 4.4 m; bypassing is longer.
    assert r.path_length > 4.4 + 1e-3


@pytest.fixture(scope="module")
def blocked_plan():
    """A failed plan (searched for seconds), shared by the tests of its message and JSON.
    Gaps of 0.55 m beside the obstacle: a robot fits (no certificate), the team does not.
    (With gaps of 0.85 m it does: the hull may reach the obstacle and the wall, only the
    robot centres keep the clearance.)"""
    return plan(corridor([Obstacle("wall-ish", 0.9, center=[3.0, 0.0], radius=0.45)]),
                iterations=200, time_budget=600)


def test_must_fail_with_reason_blocked_by_tall_obstacle(blocked_plan):
    r = blocked_plan
    assert not r.success and r.status == "budget_exhausted" and r.certificate is None
    assert "'wall-ish' (0.9 m tall) cannot be crossed" in r.message
    assert "not found within the budget" in r.message
    assert r.times.shape == (0,) and r.object.shape == (0, 3)


@pytest.mark.slow
def test_fastest_of_crossing_and_bypassing():
    # Room to bypass the low cylinder. With quick turns crossing it on the straight line
    # is faster; with slow turns (Algorithm 2 turns twice) the detour is.
    obstacles = [Obstacle("low", 0.1, center=[3.0, 0.0], radius=0.1)]
    quick = corridor(obstacles, width=3.6, team=corridor_team(rotation_speed=3.0))
    r, b = plan(quick, method="roadmap"), plan(quick, baseline="disc")
    assert b.success and r.success and b.crossed == ()
    assert r.crossed == ("low",) and r.duration < b.duration
    assert r.path_length < b.path_length
    slow = corridor(obstacles, width=3.6, team=corridor_team(rotation_speed=0.05))
    r, b = plan(slow, method="roadmap"), plan(slow, baseline="disc")
    assert r.crossed == () and r.duration == pytest.approx(b.duration)


def test_optimal_formation_meets_constraints():
    team = corridor_team()
    compact = optimal_formation(team, kind="compact")
    cross = optimal_formation(team, kind="crossing", height=0.2, diameter=0.3)
    assert compact is not None and cross is not None
    assert cross.max_height >= 0.2 - 1e-9 and cross.max_diameter >= 0.3 - 1e-9
    assert compact.reach < cross.reach and compact.object_height < cross.object_height
    assert np.all(cross.weights > 0) and cross.weights.sum() == pytest.approx(1.0)
    # No formation lifts the object above the hands.
    assert optimal_formation(team, kind="crossing", height=0.49, diameter=0.1) is None


def test_crossing_pairs_turn_angles():
    team = corridor_team()
    tri = optimal_formation(team, kind="crossing", height=0.1, diameter=0.2)
    turns = {round(abs(p[2]), 6) for p in crossing_pairs(tri, 0.2)}
    assert turns == {round(np.pi / 3, 6)}
    hexa = Team(SheetTeam(Sheet.regular(6, 0.8), 0.5), 0.1, 0.05, 0.05, 0.1, 0.3)
    f = optimal_formation(hexa, kind="crossing", height=0.1, diameter=0.1)
    assert abs(crossing_pairs(f, 0.2)[0][2]) < 1e-6          # opposite sides: no turn
    assert crossing_pairs(f, 10.0) == []                     # nothing that wide fits


def test_offset_crossings_keep_clearance():
    f = optimal_formation(corridor_team(), kind="crossing", height=0.1, diameter=0.2)
    c = 0.2
    phi, lo, hi = offset_crossings(f, c, directions=72)
    assert len(phi) and np.all(hi >= lo)
    n = np.column_stack([-np.sin(phi), np.cos(phi)])
    proj = f.robots @ n.T                                   # (N, K)
    for e in (lo, hi, (lo + hi) / 2):
        assert np.all(np.abs(proj - e).min(axis=0) >= c - 1e-12)
        # The obstacle's path passes between the outermost robots (under the sheet).
        assert np.all((proj.min(axis=0) < e) & (e < proj.max(axis=0)))
    # A triangle admits straight crossings parallel to a side, not head-on at a vertex.
    side = f.robots[1] - f.robots[0]
    a_side = np.arctan2(side[1], side[0]) % np.pi
    assert np.min(np.abs(np.angle(np.exp(2j * (phi - a_side))))) < np.radians(6)
    assert not len(offset_crossings(f, 10.0)[0])


@pytest.mark.slow
@pytest.mark.parametrize("seed,n", [(2025, 4), (2030, 3), (2032, 5), (2048, 3)])
def test_suite_plans_verify_and_dominate_baseline(seed, n):
    sc = generate_scenario(seed, n)
    r, b = plan(sc, time_budget=600), plan(sc, baseline="disc")
    for res in (r, b):
        if res.success:
            assert verify_motion(sc, res.robots, res.object,
                                 sheet_margin=res.sheet_margin).success
    assert r.success and (b.success <= r.success)


@pytest.mark.slow
def test_turned_corridor_example():
    sc = load_plan_scenario(EXAMPLES / "turned_corridor_5.yaml")
    r = plan(sc, time_budget=600)
    assert r.success and r.robots.shape[1] == 5
    assert "tall-box" in r.bypassed and "tall-box" not in r.crossed


# ------------------------------------------------------------------ bad input


def test_start_goal_errors():
    team = corridor_team()
    world = World([[0, -1], [6, -1], [6, 1], [0, 1]],
                  (Obstacle("a", 0.1, center=[3, 0], radius=0.2),))
    with pytest.raises(PlanningError) as e:
        Scenario(world, team, [3.05, 0.0], [5, 0])
    assert e.value.field == "start" and "inside obstacle 'a'" in e.value.problem
    with pytest.raises(PlanningError) as e:
        Scenario(world, team, [1, 0], [7, 0])
    assert e.value.field == "goal" and "outside the free space" in e.value.problem


def test_obstacle_errors():
    box = [[0, -1], [6, -1], [6, 1], [0, 1]]
    with pytest.raises(PlanningError) as e:
        World(box, (Obstacle("w", 0.1, center=[3, 0.9], radius=0.2),))
    assert "overlaps the walls" in e.value.problem and e.value.field == "obstacles[0]"
    with pytest.raises(PlanningError, match="overlaps obstacle"):
        World(box, (Obstacle("a", 0.1, center=[3, 0], radius=0.2),
                    Obstacle("b", 0.1, center=[3.3, 0], radius=0.2)))
    with pytest.raises(InvalidInputError):
        Obstacle("c", 0.1, center=[3, 0], radius=-0.2)
    with pytest.raises(InvalidInputError):
        Obstacle("c", 0.0, center=[3, 0], radius=0.2)


@pytest.mark.parametrize("name", ["speed", "rotation_speed", "robot_radius", "hold_height"])
def test_non_positive_team_values(name):
    with pytest.raises(InvalidInputError) as e:
        corridor_team(**{name: 0.0})
    assert e.value.field == name


def test_team_that_cannot_hold_the_object():
    # Robots 0.4 m wide cannot stand at the corners of a 0.3 m sheet.
    team = Team(SheetTeam(Sheet.regular(3, 0.3 / np.sqrt(3)), 0.2), 0.2, 0.02, 0.02, 0.1, 0.3)
    sc = Scenario(World([[0, -1], [6, -1], [6, 1], [0, 1]]), team, [1, 0], [5, 0])
    with pytest.raises(PlanningError) as e:
        plan(sc)
    assert e.value.field == "team" and "cannot hold the object" in e.value.problem


def test_scenario_file_errors(paper):
    data = plan_scenario_to_mapping(paper)
    again = plan_scenario_from_mapping(data)
    assert np.allclose(again.team.sheet.vertices, paper.team.sheet.vertices)
    bad = json.loads(json.dumps(data))
    bad["team"]["speed"] = 0
    with pytest.raises(ScenarioError) as e:
        plan_scenario_from_mapping(bad)
    assert e.value.field == "team.speed"
    bad = json.loads(json.dumps(data))
    bad["obstacles"][0]["colour"] = "red"
    with pytest.raises(ScenarioError) as e:
        plan_scenario_from_mapping(bad)
    assert e.value.field == "obstacles[0].colour"
    assert e.value.problem.startswith("unknown key; expected one of ")   # the obstacle's keys
    assert "height" in e.value.problem and "start" not in e.value.problem
    bad = json.loads(json.dumps(data))
    bad["start"] = [2.0, 0.0]
    with pytest.raises(PlanningError) as e:
        plan_scenario_from_mapping(bad)
    assert e.value.field == "start"
    bad = json.loads(json.dumps(data))
    bad["obstacles"][1]["center"] = [4.0, 0.95]
    with pytest.raises(PlanningError, match="overlaps the walls"):
        plan_scenario_from_mapping(bad)


@pytest.mark.parametrize("path, value, unit", [
    (("team", "speed"), 1e300, "m/s"), (("team", "rotation_speed"), 1e9, "rad/s"),
    (("team", "robot_radius"), 1e12, "m"), (("team", "lateral_safety"), 1e10, "m"),
    (("obstacles", 0, "height"), 1e30, "m"), (("obstacles", 1, "radius"), 1e7, "m")])
def test_scenario_values_past_the_limits_name_their_field(paper, path, value, unit):
    """Positive but absurd values are refused at the file, naming the dotted field and the
    accepted range (the limits of taut._validate), not planned with."""
    bad = json.loads(json.dumps(plan_scenario_to_mapping(paper)))
    node = bad
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ScenarioError) as e:
        plan_scenario_from_mapping(bad)
    assert e.value.field == ".".join(str(p) for p in path).replace(".0.", "[0].").replace(
        ".1.", "[1].")
    assert "exceeds the accepted range" in e.value.problem and unit in e.value.problem


# ------------------------------------------------------------------ CLI


def _app():
    from taut.cli import plan as cli_plan
    app = typer.Typer()

    @app.callback()
    def _root() -> None:
        """test root"""

    cli_plan.register(app)
    return app


@pytest.mark.slow
def test_cli_plan_json_and_figures(tmp_path, capsys):
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    rc = _app()(args=["plan", str(EXAMPLES / "paper_corridor.yaml"), "--out", str(out),
                      "--plot", str(png)], standalone_mode=False)
    assert rc == 0 and png.stat().st_size > 10_000
    data = json.loads(out.read_text())
    assert set(data) >= {"success", "message", "times", "robots", "object", "taut", "crossed",
                         "bypassed"}
    assert data["success"] is True and data["crossed"] == ["1", "2"]
    T = len(data["times"])
    assert np.asarray(data["robots"]).shape == (T, 3, 2)
    assert np.asarray(data["object"]).shape == (T, 3) and len(data["taut"]) == T
    rc = _app()(args=["plan", str(EXAMPLES / "paper_corridor.yaml"), "--algorithm2",
                      "--out", str(out)], standalone_mode=False)
    assert rc == 0 and json.loads(out.read_text())["duration"] > data["duration"]
    rc = _app()(args=["plan", str(EXAMPLES / "paper_corridor.yaml"), "--disc-baseline"],
                standalone_mode=False)
    assert rc == 1 and "no plan (" in capsys.readouterr().out


def test_failed_plan_json(blocked_plan):
    from taut.io.serialize import plan_to_dict
    d = json.loads(json.dumps(plan_to_dict(blocked_plan)))
    assert d["success"] is False and d["message"] and d["times"] == [] and d["robots"] == []
    assert d["status"] == "budget_exhausted" and "reason" not in d
    assert d["duration"] is None and d["bypassed"] == ["wall-ish"]


def test_cli_bad_file_is_typed_error(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("free_space: [[0, 0], [1, 0], [1, 1]]\nstart: [0.5, 0.2]\n")
    with pytest.raises(ScenarioError) as e:
        _app()(args=["plan", str(f)], standalone_mode=False)
    assert e.value.field in ("goal", "team")


@pytest.mark.slow
def test_formation_change_where_needed():
    # Wide hall with a low cylinder the compact formation cannot pass beside, then a
    # narrow passage only the compact formation fits: cross high, then change formation.
    team = corridor_team()
    world = World([[0, -1], [4, -1], [4, -0.6], [8, -0.6], [8, 0.6], [4, 0.6], [4, 1], [0, 1]],
                  (Obstacle("low", 0.1, center=[2, 0], radius=0.1),))
    sc = Scenario(world, team, [0.8, 0], [7.3, 0])
    assert not plan(sc, baseline="disc").success
    r = plan(sc, method="roadmap")
    assert r.success and r.crossed == ("low",) and len(r.formations) == 2
    high, low = r.formations
    assert high.object_height > low.object_height
    assert np.allclose(r.object[0, 2], high.object_height)
    assert np.allclose(r.object[-1, 2], low.object_height)
    assert verify_motion(sc, r.robots, r.object).success
    # In the narrow part the robots are within the passage, clear of its walls.
    narrow = r.object[:, 0] > 4.0 + low.reach
    assert np.all(np.abs(r.robots[narrow, :, 1]) <= 0.6 - team.clearance + 1e-9)


def test_low_prism_is_crossed():
    box = Obstacle("box", 0.12, polygon=[[2.9, -0.12], [3.1, -0.12], [3.1, 0.08], [2.9, 0.08]])
    sc = corridor([box])
    r = plan(sc, time_budget=600)
    assert r.success and r.crossed == ("box",)
    check = verify_motion(sc, r.robots, r.object)
    assert check.success and check.min_height_margin >= sc.team.height_safety - 1e-9
    assert np.isfinite(check.min_height_margin)           # it really was beneath the sheet
    assert box.diameter == pytest.approx(np.hypot(0.2, 0.2))
