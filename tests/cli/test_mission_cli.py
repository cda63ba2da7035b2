"""`taut cdpr mission`: the example end to end (slow) and the bad-input promise (one line,
exit 2, nothing computed)."""

import json
from pathlib import Path

import pytest

from cli_calls import run, one_line_error
from progress_lines import without_progress

EXAMPLE = Path(__file__).parents[2] / "examples" / "cdpr" / "warehouse.yaml"


@pytest.mark.slow
def test_example_mission_json(capsys, tmp_path):
    png, gif = tmp_path / "m.png", tmp_path / "m.gif"
    code, out, err = run(capsys, "cdpr", "mission", EXAMPLE, "--json", "--plot", png,
                         "--animate", gif)
    assert code == 0, err
    doc = json.loads(out)
    assert doc["success"] and doc["status"] == "ok"
    assert [u["task"] for u in doc["unserved"]] == ["box8"] and doc["unserved"][0]["reason"]
    assert len(doc["served"]) == 7
    for p in doc["phases"]:
        assert p["min_tension_margin_N"] >= 0 and p["min_tipping_margin_Nm"] >= 0, p
        assert p["min_cable_clearance_m"] > 0 and p["min_footprint_clearance_m"] > 0, p
    assert doc["total_time_s"] < doc["baseline_total_time_s"]
    assert png.stat().st_size > 0 and gif.stat().st_size > 0
    assert "Traceback" not in without_progress(err)


def test_missing_file(capsys, tmp_path):
    one_line_error(*run(capsys, "cdpr", "mission", tmp_path / "nope.yaml"))


def test_bad_task_mass(capsys, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(EXAMPLE.read_text().replace("mass: 4.0", "mass: -4.0"))
    one_line_error(*run(capsys, "cdpr", "mission", bad), "mass")


def test_not_a_mapping(capsys, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("- 1\n- 2\n")
    one_line_error(*run(capsys, "cdpr", "mission", bad))


@pytest.mark.parametrize("opt,name", [("--plot", "m.txt"), ("--animate", "m.png")])
def test_bad_output_suffix(capsys, tmp_path, opt, name):
    one_line_error(*run(capsys, "cdpr", "mission", EXAMPLE, opt, tmp_path / name), opt)


@pytest.mark.parametrize("value,field", [("1,x", "--active-base-offsets"),
                                         ("0.3,nan", "--active-base-offsets")])
def test_bad_active_base_offsets(capsys, value, field):
    one_line_error(*run(capsys, "cdpr", "mission", EXAMPLE, "--active-base-offsets", value),
                   field)
