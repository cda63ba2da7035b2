"""Issue 24: `taut physics` refuses a sheet model too large to simulate in one line (exit 2)
before it builds anything (1,000 robots took over 3 GB before)."""

import json

import numpy as np
import pytest

from cli_calls import one_line_error, run


@pytest.mark.parametrize("mesh, field", [(None, "sheet"), ("60", "sheet")])
def test_too_many_robots_one_line(capsys, tmp_path, mesh, field):
    pytest.importorskip("mujoco")
    from taut.sheet import Sheet
    sheet = Sheet.regular(1000, 1000.0)
    path = tmp_path / "team.json"
    path.write_text(json.dumps({"units": "mm", "hold_height": 1000.0,
                                "sheet": np.round(sheet.vertices, 6).tolist(),
                                "formation": np.round(0.8 * sheet.vertices, 6).tolist()}))
    args = ["physics", path] + ([] if mesh is None else ["--mesh", mesh])
    code, out, err = run(capsys, *args)
    one_line_error(code, out, err, f"taut: error: {field}: 1000 robots", "tendons")


def test_too_fine_mesh_one_line(capsys, tmp_path):
    pytest.importorskip("mujoco")
    from taut.app.catalog import regular_team
    path = tmp_path / "team.json"
    path.write_text(json.dumps(regular_team(64)))
    code, out, err = run(capsys, "physics", path, "--mesh", "60")
    one_line_error(code, out, err, "taut: error: mesh: ", "at mesh 60", "fits")
