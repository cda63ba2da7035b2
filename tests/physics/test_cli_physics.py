"""`taut physics`: the table, JSON, figure, exit codes and one-line errors."""

import json

import pytest
import yaml

from cli_calls import run


@pytest.fixture
def triangle(tmp_path):
    path = tmp_path / "tri.yaml"
    path.write_text(yaml.safe_dump({
        "units": "mm", "hold_height": 700.0,
        "sheet": [[600.0, 0.0], [-300.0, 519.6152422706632], [-300.0, -519.6152422706632]],
        "formation": [[480.0, -20.0], [-195.0, 369.71], [-195.0, -409.71]]}))
    return path


def test_bad_output_paths_fail_before_any_work(capsys, triangle, tmp_path):
    (tmp_path / "file").write_text("x")
    code, out, err = run(capsys, "physics", triangle, "--plot", tmp_path / "file" / "x.png")
    assert code == 2 and out == ""
    assert err.strip() == f"taut: error: --plot: '{tmp_path / 'file'}' is not a directory"
    code, _, err = run(capsys, "physics", triangle, "--video", tmp_path / "x.mp4")
    assert code == 2 and err.startswith("taut: error: --video: unsupported extension '.mp4'")
    assert len(err.strip().splitlines()) == 1


def test_missing_formation(capsys, tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"hold_height": 1.0,
                                    "sheet": [[0, 0], [1, 0], [0, 1]]}))
    code, _, err = run(capsys, "physics", path)
    assert code == 2 and err.startswith("taut: error: formation:")


@pytest.mark.slow
def test_triangle_json_and_figure(capsys, triangle, tmp_path):
    pytest.importorskip("mujoco")
    png = tmp_path / "tri.png"
    code, out, err = run(capsys, "physics", triangle, "--json", "--plot", png)
    assert code == 0, err
    data = json.loads(out)
    assert data["success"] and data["status"] == "ok"
    (state,) = data["states"]
    assert state["taut"] == [0, 1, 2] and state["kind"] == "stable" and state["held"]
    assert state["success"] and state["status"] == "ok"
    assert abs(state["tied_difference"][2]) <= 5.0
    assert png.stat().st_size > 10_000


def test_a_failed_simulation_is_shown_as_failed(capsys, triangle, tmp_path, monkeypatch):
    # A settling budget too short for the tied sheet to come to rest: every state's check
    # fails ("not_converged"); the table says FAILED instead of a displacement, the JSON
    # has nulls, the figure names it and the command exits 1.
    pytest.importorskip("mujoco")
    from taut.physics import _tol
    monkeypatch.setattr(_tol, "MAX_SETTLE_TIME", 0.1)
    code, out, err = run(capsys, "physics", triangle)
    assert code == 1, err
    assert "FAILED (not converged)" in out and "1 of 1 state(s) not confirmed" in out
    assert "failed: {1,2,3}: the tied sheet was still moving" in out
    png = tmp_path / "tri.png"
    code, out, _ = run(capsys, "physics", triangle, "--json", "--plot", png)
    data = json.loads(out)
    assert code == 1 and not data["success"] and data["status"] == "not_converged"
    (state,) = data["states"]
    assert state["status"] == "not_converged" and not state["success"]
    assert state["settled"] == [None, None, None] and state["moved"] is None
    assert png.stat().st_size > 10_000


def test_object_radius_is_checked_by_the_loader(capsys, triangle, tmp_path):
    data = yaml.safe_load(triangle.read_text())
    for bad, why in (({"radius": -1.0}, "greater than 0"), ({"radius": True}, "boolean"),
                     ({"size": 3.0}, "")):
        path = tmp_path / "bad.yaml"
        path.write_text(yaml.safe_dump({**data, "object": bad}))
        code, out, err = run(capsys, "physics", path)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
        assert err.startswith("taut: error: object.") and why in err


@pytest.mark.slow
def test_the_scenario_object_is_the_simulated_ball(capsys, triangle, tmp_path):
    # object.radius (scenario units) becomes the ball's radius, mass (kg) its mass.
    pytest.importorskip("mujoco")
    path = tmp_path / "obj.yaml"
    path.write_text(yaml.safe_dump({**yaml.safe_load(triangle.read_text()),
                                    "object": {"radius": 12.0}, "mass": 2.5}))
    code, out, err = run(capsys, "physics", path, "--json", "--mesh", "7")
    assert code == 0, err
    data = json.loads(out)
    assert data["ball_radius"] == 12.0 and data["states"][0]["held"]
