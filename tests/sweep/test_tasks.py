"""Sweep tasks against the library functions they call, and the model's symmetries."""

import numpy as np
import pytest

from taut.io import load_sheet_scenario
from taut.sheet import forward_kinematics
from taut.sweep import evaluate_chunk
from taut.sweep.tasks.fk import transform_formations


def test_fk_rows_match_forward_kinematics_of_the_transformed_formation(fk_spec, examples_dir):
    spec = fk_spec(scale=[0.7, 1.0], stretch=[1.0, 1.25], stretch_angle=[0, 35])
    rows = evaluate_chunk(spec, 0, spec.size)
    sc = load_sheet_scenario(examples_dir / "sheet" / "example2_r2_r4_353mm.yaml")
    for k in range(spec.size):
        # The transformation written out by hand for this point.
        c = sc.formation.mean(axis=0)
        a = np.deg2rad(rows["stretch_angle"][k])
        u = np.array([np.cos(a), np.sin(a)])
        m = rows["scale"][k] * (np.eye(2) + (rows["stretch"][k] - 1) * np.outer(u, u))
        form = c + (sc.formation - c) @ m.T
        res = forward_kinematics(sc.team, form)
        assert rows["n_stable"][k] == len(res.stable)
        assert rows["n_states"][k] == len(res.equilibria)
        low = res.lowest
        assert rows["lowest_taut"][k] == ",".join(map(str, low.taut))
        assert rows["lowest_height"][k] == pytest.approx(low.object[2], abs=1e-9)
        assert rows["max_tension"][k] == pytest.approx(max(low.tensions), rel=1e-12)


def test_rotation_is_a_symmetry_and_stretch_angle_has_period_180(fk_spec):
    spec = fk_spec(rotation={"range": [0, 330], "step": 30}, stretch=1.3,
                   stretch_angle=[20, 200])
    rows = evaluate_chunk(spec, 0, spec.size)
    assert len(set(rows["n_stable"].tolist())) == 1
    assert len(set(rows["lowest_taut"].tolist())) == 1
    np.testing.assert_allclose(rows["lowest_height"], rows["lowest_height"][0], rtol=1e-9)


def test_formations_beyond_the_sheet_are_reported_infeasible(fk_spec):
    spec = fk_spec(scale=[1.0, 3.0])
    rows = evaluate_chunk(spec, 0, 2)
    assert rows["feasible"].tolist() == [True, False]
    assert rows["n_stable"][1] == 0 and np.isnan(rows["lowest_height"][1])


def test_jitter_is_seeded_per_point(fk_spec):
    spec = fk_spec(jitter=[0.0, 2.0], scale=[0.8, 0.9])
    a = evaluate_chunk(spec, 0, spec.size)
    b = evaluate_chunk(spec, 1, spec.size)            # other chunk bounds, same points
    np.testing.assert_array_equal(a["lowest_height"][1:], b["lowest_height"])
    forms = transform_formations(np.eye(2), {"scale": np.ones(2), "stretch": np.ones(2),
                                             "stretch_angle": np.zeros(2),
                                             "rotation": np.zeros(2),
                                             "jitter": np.array([1.0, 1.0])},
                                 np.array([7, 8], dtype=np.uint64))
    assert not np.allclose(forms[0], forms[1])


def test_cdpr_workspace_row_equals_the_workspace_analysis():
    from taut.cdpr import grid_points, wrench_feasible_workspace
    from taut.io import load_cdpr_model
    from taut.sweep import sweep_from_mapping

    spec = sweep_from_mapping({"task": "cdpr_workspace", "base": "fastkit",
                               "options": {"grid": [6, 1, 4]},
                               "parameters": {"base_separation": [6.0, 5.0]}})
    rows = evaluate_chunk(spec, 0, 2)
    robot = load_cdpr_model("fastkit")
    pts, _ = grid_points(robot.desired_workspace, (6, 1, 4))
    ws = wrench_feasible_workspace(robot, pts)
    assert rows["coverage"][0] == pytest.approx(np.mean(ws.feasible))
    assert rows["coverage_tipping"][0] == pytest.approx(np.mean(ws.feasible_tipping))
    assert rows["n_points"][0] == 24 and rows["message"][0] == ""


def test_cdpr_invalid_variant_is_a_row_with_its_reason():
    from taut.sweep import sweep_from_mapping

    spec = sweep_from_mapping({"task": "cdpr_workspace", "base": "fastkit",
                               "options": {"grid": [3, 1, 2]},
                               "parameters": {"t_max": [1.0]}})
    rows = evaluate_chunk(spec, 0, 1)
    assert np.isnan(rows["coverage"][0]) and "t_m" in rows["message"][0]
