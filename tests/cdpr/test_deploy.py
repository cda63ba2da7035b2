"""Deployment planning of FASTKIT's mobile bases, and the `twist-set` / `deploy` commands."""

import json

import numpy as np
import pytest
import typer

from taut.cdpr import (distribute_tensions, grid_points, tipping_moments, with_stabilisers,
                       wrench_feasible)
from taut.cdpr.deploy import place_bases, plan_deployment, workspace_box
from taut.cdpr.twist import available_twist_set
from taut.cli.cdpr_motion import add_commands
from taut.errors import InvalidInputError, TautError

# FASTKIT's 5 m long workspace (x), as a thin 0.1 m deep slab, 0.8 m high: the part of the
# paper's 5 m x 2 m that the 45 N cables can hold with the 7 kg payload (see the note).
BOX = np.array([[-2.5, -0.05, 0.2], [2.5, 0.05, 1.0]])
TWIST = np.array([1.0, 0, 0, 0, 0, 0])          # the paper's 1 m/s platform speed


@pytest.fixture(scope="module")
def deployment():
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"), True)
    return plan_deployment(robot, BOX, required_twist=TWIST, maxiter=3, popsize=5,
                           grid=(6, 2, 3), verify_grid=(11, 3, 5), seed=0)


def test_fastkit_deployment_is_verified_with_tipping(deployment):
    res = deployment
    assert res.feasible and res.reason == ""
    assert res.margin > 0 and res.twist_margin > 0
    # independent re-check on a different, finer grid of the box with the issue-5 tests
    pts, _ = grid_points(BOX, (21, 3, 9))
    assert wrench_feasible(res.robot, pts, tipping=True).all()
    # ... and with explicit tensions: an LP distribution that respects tipping, whose
    # tensions are within limits and whose edge moments are all <= 0
    tr = distribute_tensions(res.robot, pts[::7], "lp_min_sum", tipping=True)
    assert tr.feasible.all()
    assert np.all(tr.tensions >= res.robot.t_min - 1e-6)
    assert np.all(tr.tensions <= res.robot.t_max + 1e-6)
    tm = tipping_moments(res.robot, pts[::7], tr.tensions)
    assert tm.stable.all()
    # the required twist is available everywhere
    assert available_twist_set(res.robot, pts).contains(TWIST).all()
    # bases actually moved to the planned poses
    for b in res.robot.bases:
        np.testing.assert_allclose(b.pose, res.base_poses[b.name])


def test_model_placement_is_worse(deployment):
    """The shipped placement (bases at +-3 m) is not wrench-feasible over this box with
    tipping: the planner improved on it."""
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"), True)
    pts, _ = grid_points(BOX, (11, 3, 5))
    assert not wrench_feasible(robot, pts, tipping=True).all()


def test_full_height_box_reports_why(fastkit):
    """With the 7 kg payload and 45 N cables no placement holds the platform 2 m high over
    5 m: the planner says so and names the worst point."""
    res = plan_deployment(with_stabilisers(fastkit, True), [[-2.5, -0.05, 0.0],
                                                            [2.5, 0.05, 2.0]],
                          maxiter=1, popsize=4, grid=(5, 1, 3), verify_grid=(5, 2, 3))
    assert not res.feasible
    assert res.margin < 0
    assert "not wrench-feasible with tipping" in res.reason
    assert not res.point_feasible.all()


def test_place_bases(fastkit):
    r = place_bases(fastkit, {"active": (-3.5, 0.2, 0.1)})
    assert np.allclose(r.bases[0].pose, (-3.5, 0.2, 0.1))
    assert np.allclose(r.bases[1].pose, fastkit.bases[1].pose)
    assert r.bounds[0, 0] < fastkit.bounds[0, 0]
    with pytest.raises(InvalidInputError):
        place_bases(fastkit, {"ghost": (0, 0, 0)})


def test_workspace_validation(fastkit):
    assert workspace_box([-1, 1, -0.1, 0.1, 0.5, 1.0]).shape == (2, 3)
    with pytest.raises(InvalidInputError, match="no volume"):
        workspace_box([[-2.5, 0.0, 0.2], [2.5, 0.0, 2.2]])
    with pytest.raises(InvalidInputError, match="no volume"):
        workspace_box([1, -1, 0, 1, 0, 1])
    with pytest.raises(InvalidInputError, match="NaN"):
        workspace_box([0, 1, 0, 1, 0, float("nan")])
    with pytest.raises(InvalidInputError):
        plan_deployment(fastkit, BOX, required_twist=[1.0, 0.0])


def _app():
    app = typer.Typer()
    sub = typer.Typer()
    add_commands(sub)
    app.add_typer(sub, name="cdpr")
    return app


def _run(args, capsys):
    _app()(args=args, standalone_mode=False)
    return capsys.readouterr().out


def test_cli_twist_set(capsys, tmp_path):
    out = json.loads(_run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0",
                           "--json", "--plot", str(tmp_path / "ats.png")], capsys))
    assert out["moving"] == ["active"]
    assert all(a >= b - 1e-9 for a, b in zip(out["positive"], out["bases_fixed"]["positive"]))
    assert (tmp_path / "ats.png").stat().st_size > 1000
    nav = json.loads(_run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0",
                           "--mode", "navigation", "--json"], capsys))
    assert nav["positive"][0] == pytest.approx(0.2) and nav["positive"][2] == 0.0
    text = _run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0"], capsys)
    assert "vx" in text and "fixed" in text


@pytest.mark.parametrize("args, field", [
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--moving", "ghost"], "mode.moving"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--mode", "fly"], "mode"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--cable-speed", "-1"], "limits.cable"),
    (["twist-set", "fastkit", "--pose", "nan", "0", "1"], "pose"),
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "0", "0.2", "1"], "workspace"),
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "nan", "0.2", "1"], "workspace"),
    (["deploy", "nosuchmodel", "--workspace", "-1", "1", "-1", "1", "0.2", "1"], "model"),
])
def test_cli_errors(args, field):
    with pytest.raises(TautError) as exc:
        _app()(args=["cdpr", *args], standalone_mode=False)
    assert exc.value.field == field


def test_cli_deploy(capsys, tmp_path):
    out = json.loads(_run(["cdpr", "deploy", "fastkit", "--workspace", "-1.0", "1.0", "-0.05",
                           "0.05", "0.4", "0.9", "--stabilisers", "--maxiter", "1", "--json",
                           "--plot", str(tmp_path / "d.png")], capsys))
    assert set(out["base_poses"]) == {"active", "passive"}
    assert out["feasible"] is (out["feasible_points"] == out["points"])
    assert (tmp_path / "d.png").stat().st_size > 1000


def test_cli_deploy_text_with_disturbance(capsys):
    text = _run(["cdpr", "deploy", "fastkit", "--workspace", "-0.5", "0.5", "-0.05", "0.05",
                 "0.5", "0.8", "--stabilisers", "--maxiter", "1", "--disturbance", "2", "2",
                 "2", "0", "0", "0", "--twist", "0.5", "0", "0", "0", "0", "0"], capsys)
    assert "active: x=" in text and "worst capacity margin" in text
