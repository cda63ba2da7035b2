"""Cable kinematics (W as the length Jacobian, eq. 18), workspaces and the cdpr CLI."""

import json

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from taut.cdpr import (cable_state, grid_points, rotation_matrices, with_stabilisers,
                       wrench_feasible_workspace)
from taut.cli import main

from cdpr_helpers import random_poses


@settings(max_examples=30, deadline=None)
@given(st.tuples(*[st.floats(-3.0, 3.0)] * 3))
def test_rotation_matches_scipy_zyx(rpy):
    R = rotation_matrices(np.array([rpy]))[0]
    ref = Rotation.from_euler("ZYX", rpy[::-1]).as_matrix()
    np.testing.assert_allclose(R, ref, atol=1e-12)


@pytest.mark.parametrize("name", ["fastkit", "ipanema"])
def test_wrench_matrix_is_minus_length_jacobian(request, name):
    """d(lengths) = -W^T [dp; dtheta] for a small twist (dtheta about world axes)."""
    robot = request.getfixturevalue(name)
    g = np.random.default_rng(0)
    for pose in random_poses(robot, 5, seed=3, margin=0.15):
        st0 = cable_state(robot, pose)
        d = g.normal(size=6) * 1e-7
        R1 = Rotation.from_rotvec(d[3:]).as_matrix() @ st0.R
        ypr = Rotation.from_matrix(R1).as_euler("ZYX")
        pose1 = np.r_[pose[:3] + d[:3], ypr[::-1]]
        dl = cable_state(robot, pose1).lengths - st0.lengths
        np.testing.assert_allclose(dl, -st0.W.T @ d, atol=1e-12)


def test_lengths_and_units(fastkit):
    st_ = cable_state(fastkit, random_poses(fastkit, 50, seed=1))
    np.testing.assert_allclose(np.linalg.norm(st_.unit, axis=2), 1.0)
    assert st_.W.shape == (50, 6, 8) and st_.lengths.min() > 0


def test_grid_points():
    pts, shape = grid_points([[0, 0, 0], [1, 0, 2]], (3, 5, 5))
    assert shape == (3, 1, 5) and pts.shape == (15, 3)
    assert np.all(pts[:, 1] == 0)


def test_workspace_tipping_subset_and_coverage(fastkit):
    pts, shape = grid_points(fastkit.desired_workspace, (21, 1, 11))
    ws = wrench_feasible_workspace(fastkit, pts, shape=shape)
    assert not np.any(ws.feasible_tipping & ~ws.feasible)
    assert 0.0 < ws.coverage_tipping < ws.coverage < 1.0
    dep = wrench_feasible_workspace(with_stabilisers(fastkit), pts, shape=shape)
    assert dep.coverage_tipping >= ws.coverage_tipping
    np.testing.assert_array_equal(dep.feasible, ws.feasible)
    # Orientation sweep: feasible at all orientations => feasible at the level one.
    ori = [[0, 0, 0], [0, 0, 0.2], [0.1, 0, 0]]
    sw = wrench_feasible_workspace(fastkit, pts, orientations=ori)
    assert sw.per_orientation.shape == (len(pts), 3)
    assert not np.any(sw.feasible & ~ws.feasible)
    np.testing.assert_array_equal(sw.per_orientation[:, 0], ws.feasible_tipping)


def test_fixed_frame_workspace(ipanema):
    pts, shape = grid_points(ipanema.desired_workspace, (5, 5, 5))
    ws = wrench_feasible_workspace(ipanema, pts, shape=shape)
    assert ws.feasible_tipping is None and ws.coverage_tipping is None
    assert ws.coverage > 0.5


def test_cli_tensions_json(capsys):
    assert main(["cdpr", "tensions", "fastkit", "--pose", "0", "0", "0.6", "--json",
                 "--method", "qp_min_norm", "--tipping"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["feasible"] is True and len(out["tensions"]) == 8
    assert out["residual"] < 1e-10 and max(out["tipping_moments"]) <= 0


def test_cli_tensions_table(capsys):
    assert main(["cdpr", "tensions", "ipanema", "--pose", "0", "0", "1.5", "--rpy", "0",
                 "0", "0.1"]) == 0
    out = capsys.readouterr().out
    assert "C8" in out and "feasible: yes" in out


def test_cli_wrench_set(capsys):
    assert main(["cdpr", "wrench-set", "fastkit", "--pose", "0", "0", "0.6", "--json",
                 "--external-wrench", "2", "2", "2", "0.1", "0.1", "0.1"]) == 0
    out = json.loads(capsys.readouterr().out)
    a, b = out["tension_limits_only"], out["with_tipping"]
    for k in a["capacity_positive"]:
        assert b["capacity_positive"][k] <= a["capacity_positive"][k] + 1e-6
    assert a["gravity_feasible"] and len(a["halfspaces"]["h"]) > 12
    assert main(["cdpr", "wrench-set", "fastkit", "--pose", "0", "0", "0.6"]) == 0
    assert "fz" in capsys.readouterr().out


def test_cli_workspace_plot(tmp_path, capsys):
    png = tmp_path / "ws.png"
    assert main(["cdpr", "workspace", "fastkit", "--grid", "11", "1", "6", "--plot",
                 str(png), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert png.stat().st_size > 10_000
    assert out["coverage_tipping"] <= out["coverage"] and len(out["feasible"]) == 66
    assert main(["cdpr", "workspace", "ipanema", "--grid", "3", "3", "3", "--plot",
                 str(tmp_path / "ip.png")]) == 0
    assert "coverage" in capsys.readouterr().out


def test_axis_capacity_figure(tmp_path, fastkit):
    from taut.cdpr import axis_capacities
    from taut.viz.cdpr import plot_axis_capacities
    pose = [0, 0, 0.6]
    fig = plot_axis_capacities(axis_capacities(fastkit, pose, tipping=False),
                               axis_capacities(fastkit, pose, tipping=True), tmp_path / "cap.png")
    assert (tmp_path / "cap.png").stat().st_size > 5_000
    assert len(fig.axes) == 2


def test_cli_sweep_and_capacity_plot(tmp_path, capsys):
    assert main(["cdpr", "workspace", "fastkit", "--grid", "11", "1", "6", "--json"]) == 0
    level = json.loads(capsys.readouterr().out)
    assert main(["cdpr", "workspace", "fastkit", "--grid", "11", "1", "6", "--json",
                 "--sweep", "0.1"]) == 0
    swept = json.loads(capsys.readouterr().out)
    assert len(swept["orientations"]) == 7
    assert all(b <= a for a, b in zip(level["feasible"], swept["feasible"]))
    png = tmp_path / "cap.png"
    assert main(["cdpr", "wrench-set", "fastkit", "--pose", "-1.5", "0", "0.8", "--plot",
                 str(png)]) == 0
    assert png.stat().st_size > 5_000 and "figure written" in capsys.readouterr().out


def test_the_workspace_pose_limit_is_the_librarys(fastkit):
    """MAX_WORKSPACE_POSES bounds a grid and the points x orientations of one workspace, in
    the library (the CLI and the sweep file read the same constant), before any work."""
    from taut._validate import MAX_WORKSPACE_POSES
    from taut.cdpr import wrench_feasible_workspace
    from taut.errors import InvalidInputError

    box = fastkit.desired_workspace
    side = int(round(MAX_WORKSPACE_POSES ** 0.5))
    pts, _ = grid_points(box, (side, 1, MAX_WORKSPACE_POSES // side))     # at the limit
    assert len(pts) == MAX_WORKSPACE_POSES
    with pytest.raises(InvalidInputError, match="grid"):
        grid_points(box, (side, 1, MAX_WORKSPACE_POSES // side + 1))
    few = pts[: MAX_WORKSPACE_POSES // 6]
    with pytest.raises(InvalidInputError, match="orientations"):
        wrench_feasible_workspace(fastkit, few, orientations=np.zeros((7, 3)))
