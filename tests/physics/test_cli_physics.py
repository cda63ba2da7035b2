"""`taut physics`: the table, JSON, figure, exit codes and one-line errors."""

import json

import pytest
import yaml

from taut.cli import main


def run(capsys, *args):
    code = main(list(map(str, args)))
    out, err = capsys.readouterr()
    return code, out, err


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
    assert state["taut"] == [0, 1, 2] and state["status"] == "stable" and state["held"]
    assert abs(state["tied_difference"][2]) <= 5.0
    assert png.stat().st_size > 10_000
