"""The `taut fk` command: output formats, example files, one-line errors."""

import json

import numpy as np
import pytest

from json_compare import assert_same_document
from taut.cli import main
from cli_calls import run
from progress_lines import without_progress

EXAMPLES = sorted((__import__("pathlib").Path(__file__).parents[2] / "examples" / "sheet")
                  .glob("*.yaml"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_examples_match_expected_output(capsys, path):
    code, out, err = run(capsys, "fk", path, "--json")
    assert code == 0 and without_progress(err) == ""
    got = json.loads(out)
    want = json.loads(path.with_suffix(".expected.json").read_text())
    assert [e["taut"] for e in got["equilibria"]] == [e["taut"] for e in want["equilibria"]]
    assert_same_document(got, want)         # the whole document: every key and number


def test_json_schema(capsys, examples_dir):
    code, out, _ = run(capsys, "fk", examples_dir / "sheet" / "example1.yaml", "--json",
                       "--method", "exhaustive", "--mass", "2")
    doc = json.loads(out)
    assert set(doc) == {"method", "equilibria", "funnel", "units"}
    assert doc["units"]["equilibria.tensions"] == "N" and doc["units"]["equilibria.object"] == "mm"
    assert doc["funnel"] == {"combinations": 5, "form_closure": 5, "cqp_feasible": 3,
                             "height_feasible": 3, "force_closure": 3}
    e = doc["equilibria"][0]
    assert set(e) == {"taut", "object", "contact", "weights", "tensions", "cable_lengths",
                      "kind", "stable"}
    assert e["taut"] == [0, 1, 2] and e["stable"] is True and len(e["tensions"]) == 3


def test_table_output_numbers_robots_from_one(capsys, examples_dir):
    code, out, _ = run(capsys, "fk", examples_dir / "sheet" / "example2_r2_r4_353mm.yaml")
    assert code == 0
    assert "{4,5,8}" in out and "stable" in out and "6 solution(s), 1 stable" in out


def test_plot_is_written(capsys, tmp_path, examples_dir):
    target = tmp_path / "fig.png"
    code, _, _ = run(capsys, "fk", examples_dir / "sheet" / "example1.yaml", "--plot", target)
    assert code == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def write(tmp_path, text, name="s.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


GOOD = """hold_height: 1.0
sheet: [[0, 0], [1, 0], [1, 1], [0, 1]]
formation: [[0.2, 0.2], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]]
"""


@pytest.mark.parametrize("text,fragment", [
    (GOOD + "colour: red\n", "colour: unknown key"),
    (GOOD.replace("hold_height: 1.0", "hold_height: -2"), "hold_height: must be positive"),
    (GOOD.replace("hold_height: 1.0\n", ""), "hold_height: required key is missing"),
    (GOOD.replace("[1, 1], [0, 1]]", "[1, 1], [0.5, 1.3], [0, 1]]"), "formation: has 4 robots"),
    (GOOD.replace("[0.8, 0.8], [0.2", "[3.0, 3.0], [0.2"), "formation: robots"),
    (GOOD.replace("[1, 0], [1, 1]", "[1, 1], [1, 0]"), "polygon is not convex"),
    (GOOD.replace("[1, 0],", "[1, zero],"), "sheet[1][1]"),
    (GOOD + "mass: .nan\n", "mass"),
    ("hold_height: [1, 2\n", "invalid YAML"),
    ("- 1\n- 2\n", "top level must be a mapping"),
    (GOOD.replace("formation:", "# formation:"), "formation: required key is missing"),
])
def test_bad_scenarios_one_line_exit_2(capsys, tmp_path, text, fragment):
    code, out, err = run(capsys, "fk", write(tmp_path, text))
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("taut: error: ")
    assert fragment in err


def test_bad_json_scenario(capsys, tmp_path):
    code, _, err = run(capsys, "fk", write(tmp_path, '{"hold_height": 1,', "s.json"))
    assert code == 2 and "invalid JSON" in err


@pytest.mark.parametrize("args,fragment", [
    (["fk", "missing.yaml"], "missing.yaml: file not found"),
    (["fk"], "missing"),
    (["fk", "x.yaml", "--method", "magic"], "--method"),
    (["fk", "x.yaml", "--mass", "abc"], "--mass"),
    (["fk", "x.yaml", "--frobnicate"], "--frobnicate: no such option"),
    (["fk", "x.yaml", "--mass"], "--mass: requires an argument"),
    (["cdpr", "deploy", "fastkit", "--workspace", "0", "1"], "--workspace: requires 6"),
    (["nonsense"], "nonsense"),
])
def test_usage_errors_one_line_exit_2(capsys, args, fragment):
    code, out, err = run(capsys, *args)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and fragment in err


def test_no_arguments_prints_help(capsys):
    code, out, _ = run(capsys)
    assert code == 0 and "fk" in out


def test_version(capsys):
    import taut
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"taut {taut.__version__}"


def test_no_equilibrium_prints_the_library_reason(capsys, tmp_path):
    """The reason is the library's (``FKResult.message``), in the table and in the JSON."""
    from taut.sheet import Sheet, SheetTeam, forward_kinematics

    path = write(tmp_path, GOOD.replace("hold_height: 1.0", "hold_height: 0.1"))
    res = forward_kinematics(SheetTeam(Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 0.1),
                             [[0.2, 0.2], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]])
    assert not res.success and res.message.startswith("no equilibrium: 1 state(s) discarded")
    code, out, _ = run(capsys, "fk", path)
    assert code == 1 and out.rstrip().endswith(res.message)
    code, out, _ = run(capsys, "fk", path, "--json")
    assert code == 1 and json.loads(out)["message"] == res.message
