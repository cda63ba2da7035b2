"""Wrench-closure workspace through the workspace front end, and the exits'-box
condition (a platform that must stay inside the exits' bounding box)."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.cdpr import grid_points, wrench_closure, wrench_feasible_workspace
from taut.cdpr.workspace.exit_box import exits_box, platform_inside_exits
from taut.io.cdpr_model import cdpr_model_from_mapping, load_cdpr_model, preset_path
from taut.io.files import read_mapping

PRESETS = ("fastkit", "fastkit_fc")
#: A box of extra external wrenches around the origin (N, N m): the required set then has
#: the origin in its interior, so wrench-feasible => wrench closure.
AROUND_ZERO = np.array([[sx * 2.0, sy * 2.0, sz * 2.0, 0.0, 0.0, 0.0]
                        for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
                       + [[0, 0, 0, sm * 0.2 * (k == 0), sm * 0.2 * (k == 1), sm * 0.2 * (k == 2)]
                          for sm in (-1, 1) for k in range(3)])


@pytest.fixture(scope="module", params=PRESETS)
def robot(request):
    return load_cdpr_model(request.param)


def _grid(robot, shape=(13, 3, 7)):
    box = np.array(robot.desired_workspace, dtype=float)
    box[:, 1] = (-0.3, 0.3)
    return grid_points(box, shape)


def test_closure_contains_feasible_when_the_required_set_surrounds_zero(robot):
    """Feasible for every wrench of a set with the origin inside => the cable cone is all
    of R^6 => closure: WCW ⊇ WFW over a 3D grid of both presets (no gravity)."""
    free = replace(robot, gravity=(0.0, 0.0, 0.0))
    pts, shape = _grid(robot)
    ws = wrench_feasible_workspace(free, pts, shape=shape, external_wrench=AROUND_ZERO,
                                   closure=True)
    assert ws.closure is not None and not np.any(ws.feasible & ~ws.closure)
    if robot.name == "fastkit_fc":
        assert ws.feasible.sum() >= 10 and ws.closure.sum() > ws.feasible.sum()
    else:                                   # suspended: no closure, so nothing feasible
        assert not ws.closure.any() and not ws.feasible.any()
    # closure does not depend on gravity: the front end agrees with the per-pose test
    np.testing.assert_array_equal(ws.closure, wrench_closure(robot, pts))


def test_closure_implies_feasible_with_unbounded_tensions(robot):
    """The other direction of the sandwich: with closure any wrench, gravity included, is
    balanced by tensions >= t_min once t_max is large (here 1e7 N)."""
    big = replace(robot, cables=tuple(replace(c, t_max=1e7) for c in robot.cables))
    pts, shape = _grid(robot, (13, 1, 7))
    ws = wrench_feasible_workspace(big, pts, shape=shape, closure=True)
    assert ws.closure is not None
    assert not np.any(ws.closure & ~ws.feasible)
    assert ws.coverage_closure == pytest.approx(ws.closure.mean())


def test_closure_at_every_swept_orientation(robot):
    pts, shape = _grid(robot, (9, 1, 5))
    ori = np.array([[0, 0, 0], [0.2, 0, 0], [0, -0.25, 0.1]])
    ws = wrench_feasible_workspace(robot, pts, orientations=ori, shape=shape, closure=True)
    per = np.stack([wrench_closure(robot, np.hstack([pts, np.tile(o, (len(pts), 1))]))
                    for o in ori], axis=1)
    np.testing.assert_array_equal(ws.closure, per.all(axis=1))
    plain = wrench_feasible_workspace(robot, pts, shape=shape)
    assert plain.closure is None and plain.coverage_closure is None


# --- the exits' bounding box ----------------------------------------------------------

def _with_flag(name):
    data = read_mapping(preset_path(name))
    data["platform_inside_exits"] = True
    return cdpr_model_from_mapping(data)


def test_model_file_flag_round_trip():
    assert load_cdpr_model("fastkit").platform_inside_exits is False
    assert _with_flag("fastkit").platform_inside_exits is True
    box = exits_box(load_cdpr_model("fastkit"))
    np.testing.assert_allclose(box, [[-2.6, -0.55, 0.0], [2.6, 0.55, 2.4]])


angle = st.floats(-0.6, 0.6)


@settings(max_examples=60, deadline=None)
@given(x=st.floats(-2.6, 2.6), y=st.floats(-0.5, 0.5), z=st.floats(0.0, 2.4), r=angle,
       p=angle, w=angle)
def test_inside_matches_sampling_the_platform_body(x, y, z, r, p, w):
    """Corner test against brute force: a dense lattice of the platform box (faces
    included) is inside the exits' box iff the corners are."""
    robot = load_cdpr_model("fastkit")
    pose = np.array([x, y, z, r, p, w])
    got = platform_inside_exits(robot, pose)          # one pose: one bool
    lo, hi = robot.attach_local.min(0), robot.attach_local.max(0)
    s = np.linspace(0, 1, 7)
    lat = np.stack(np.meshgrid(s, s, s, indexing="ij"), -1).reshape(-1, 3)
    body = lo + lat * (hi - lo)
    cr, cp, cy = np.cos([r, p, w])
    sr, sp, sy = np.sin([r, p, w])
    R = np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                  [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                  [-sp, cp * sr, cp * cr]])
    world = pose[:3] + body @ R.T
    box = exits_box(robot)
    brute = bool(np.all((world >= box[0] - 1e-9) & (world <= box[1] + 1e-9)))
    assert got == brute


def test_exits_box_is_a_fourth_workspace_condition():
    flagged = _with_flag("fastkit")
    pts, shape = grid_points([[-2.5, 0.0, 0.2], [2.5, 0.0, 2.2]], (41, 1, 21))
    ws = wrench_feasible_workspace(flagged, pts, shape=shape)
    plain = wrench_feasible_workspace(load_cdpr_model("fastkit"), pts, shape=shape)
    assert ws.inside_exits is not None and plain.inside_exits is None
    # level platform, 0.6 m long, exits at x = +-2.6 m: inside iff |x| <= 2.3 m
    np.testing.assert_array_equal(ws.inside_exits, np.abs(pts[:, 0]) <= 2.3 + 1e-9)
    assert ws.coverage_inside == pytest.approx(
        (ws.feasible_tipping & ws.inside_exits).mean())
    assert ws.coverage_inside < ws.coverage_tipping == plain.coverage_tipping
    np.testing.assert_array_equal(ws.binding == "exits_box",
                                  ws.feasible_tipping & ~ws.inside_exits)
    np.testing.assert_array_equal(ws.binding[ws.binding != "exits_box"],
                                  plain.binding[ws.binding != "exits_box"])


# --- CLI --------------------------------------------------------------------------------

def test_cli_closure_json_matches_the_api(capsys):
    import json

    from taut.cli import main
    assert main(["cdpr", "workspace", "fastkit_fc", "--grid", "9", "1", "5", "--closure",
                 "--json"]) in (0, None)
    out = json.loads(capsys.readouterr().out)
    robot = load_cdpr_model("fastkit_fc")
    pts, _ = grid_points(robot.desired_workspace, (9, 1, 5))
    np.testing.assert_array_equal(np.array(out["closure"], bool), wrench_closure(robot, pts))
    assert out["coverage_closure"] == pytest.approx(np.mean(out["closure"]))
    assert set(out["binding"]) <= {"", "limits", "tipping"}


def test_cli_model_file_with_exits_box_and_3d_plot(tmp_path, capsys):
    import yaml

    from taut.cli import main
    data = read_mapping(preset_path("fastkit"))
    data["platform_inside_exits"] = True
    model = tmp_path / "m.yaml"
    model.write_text(yaml.safe_dump(data))
    fig = tmp_path / "ws.png"
    code = main(["cdpr", "workspace", str(model), "--grid", "9", "3", "4", "--box", "-2.5",
                 "2.5", "-0.4", "0.4", "0.3", "2.0", "--plot", str(fig)])
    out = capsys.readouterr().out
    assert code in (0, None) and fig.stat().st_size > 10_000
    assert "+ inside exits' box" in out
