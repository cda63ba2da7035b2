"""`taut ik` and `taut simulate`: outputs, trajectory CSV parsing, one-line errors."""

import json
from pathlib import Path

import numpy as np
import pytest

from cli_calls import run, one_line_error
from taut.errors import InvalidTrajectoryError, ScenarioError
from taut.io.trajectory import load_trajectory, parse_trajectory, save_trajectory
from taut.sheet import Sheet, forward_kinematics
from taut.sheet import SheetTeam
from progress_lines import without_progress

TRAJ = Path(__file__).parents[2] / "examples" / "sheet" / "trajectories"
SCENARIO = TRAJ / "square4.yaml"
JUMP = TRAJ / "square4_jump.csv"


def test_ik_json_round_trips_through_fk(capsys):
    code, out, err = run(capsys, "ik", SCENARIO, "--object", "-0.1", "0.2", "0.9",
                         "--contact", "0.2", "0.1", "--json")
    assert code == 0 and without_progress(err) == ""
    doc = json.loads(out)
    assert set(doc) >= {"formation", "object", "contact", "weights", "tensions", "angles"}
    assert len(doc["formation"]) == 4 and len(doc["tensions"]) == 4      # mass in file
    fk = forward_kinematics(SheetTeam(Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]]), 1.5),
                            np.array(doc["formation"]))
    assert any(e.stable and len(e.taut) == 4
               and np.allclose(e.object, [-0.1, 0.2, 0.9], atol=1e-9) for e in fk.equilibria)


def test_ik_table_and_heading(capsys):
    code, out, _ = run(capsys, "ik", SCENARIO, "--object", "0", "0", "1", "--heading",
                         "1.5707963267948966")       # rad, as inverse_kinematics(heading=)
    assert code == 0
    assert "all 4 cables taut" in out and out.count("\n") == 6
    # At heading 90 deg robot 1 (sheet corner (1, 1)) stands at (-a, a).
    x, y = map(float, out.splitlines()[2].split()[1:3])
    assert x < 0 < y and abs(abs(x) - y) < 1e-9


@pytest.mark.parametrize("args, words", [
    (["--object", "0", "0", "2"], ["unreachable", "not below the holding height"]),
    (["--object", "0", "0", "0.05"], ["unreachable", "too deep"]),
])
def test_ik_unreachable_exits_1_with_one_line(capsys, args, words):
    code, out, err = run(capsys, "ik", SCENARIO, *args)
    assert code == 1 and out == "" and err.count("\n") == 1, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("args, words", [
    (["--object", "0", "0", "1", "--contact", "5", "0"], ["contact", "not strictly inside"]),
    (["--object", "0", "0"], ["object"]),
    (["--object", "0", "0", "1", "--mass", "-2"], ["--mass", "positive"]),
])
def test_ik_errors_are_one_line(capsys, args, words):
    one_line_error(*run(capsys, "ik", SCENARIO, *args), *words)


def test_ik_missing_scenario(capsys, tmp_path):
    one_line_error(*run(capsys, "ik", tmp_path / "nope.yaml", "--object", "0", "0", "1"),
                   "file not found")


def test_simulate_summary_json_and_plot(capsys, tmp_path):
    code, out, err = run(capsys, "simulate", SCENARIO, "--trajectory", JUMP)
    assert code == 0 and without_progress(err) == ""
    assert "1 jump(s)" in out and "step 120" in out and "{1,2,3} -> {1,3,4}" in out
    code, out, _ = run(capsys, "simulate", SCENARIO, "--trajectory", JUMP, "--json")
    doc = json.loads(out)
    assert len(doc["object"]) == 201 and len(doc["time"]) == 201
    assert [e["kind"] for e in doc["events"]] == ["jump"] and doc["events"][0]["step"] == 120
    assert doc["tensions"] is not None
    target = tmp_path / "sim.png"
    code, _, _ = run(capsys, "simulate", SCENARIO, "--trajectory", JUMP, "--plot", target)
    assert code == 0 and target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def write(tmp_path, text, name="t.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


GOOD = "0,0.8,0.8,-0.8,0.8,-0.8,-0.8,0.8,-0.8\n"


@pytest.mark.parametrize("text, words", [
    (GOOD + "1,0.8,0.8,-0.8\n", ["t.csv:2", "has 4 columns, expected 9"]),
    (GOOD + "0,0.8,0.8,-0.8,0.8,-0.8,-0.8,0.8,-0.8\n", ["t.csv:2", "strictly increasing"]),
    (GOOD + "1,nan,0.8,-0.8,0.8,-0.8,-0.8,0.8,-0.8\n", ["t.csv:2", "NaN"]),
    (GOOD + "1,x,0.8,-0.8,0.8,-0.8,-0.8,0.8,-0.8\n", ["t.csv:2", "not a number"]),
    ("# nothing\n", ["t.csv", "no data rows"]),
    ("0,1,2,3,4\n", ["t.csv:1", "expected 1 + 2N"]),
    (GOOD.replace("0,0.8", "0,9.8"), ["formations", "robots 1 and", "tear"]),
    ("0,0.8,0.8,-0.8,0.8,-0.8,-0.8\n1,0.8,0.8,-0.8,0.8,-0.8,-0.8\n", ["3 robots", "4 vertices"]),
])
def test_simulate_bad_trajectories_are_one_line(capsys, tmp_path, text, words):
    path = write(tmp_path, text)
    one_line_error(*run(capsys, "simulate", SCENARIO, "--trajectory", path), *words)


def test_simulate_infeasible_step_is_reported(capsys, tmp_path):
    tr = load_trajectory(JUMP)
    R = tr.formations[:10].copy()
    R[6, 2] = [3.0, -3.0]
    path = tmp_path / "bad.csv"
    save_trajectory(path, tr.time[:10], R)
    one_line_error(*run(capsys, "simulate", SCENARIO, "--trajectory", path),
                   "formations", "step 6")


def test_trajectory_parsing_header_comments_and_round_trip(tmp_path):
    text = "# robots on a square\nt,x1,y1,x2,y2,x3,y3,x4,y4\n\n" + GOOD + \
        "0.5,0.7,0.8,-0.8,0.8,-0.8,-0.8,0.8,-0.8\n"
    tr = parse_trajectory(text.splitlines())
    assert tr.n_robots == 4 and len(tr) == 2
    np.testing.assert_allclose(tr.time, [0, 0.5])
    np.testing.assert_allclose(tr.formations[1, 0], [0.7, 0.8])
    path = tmp_path / "rt.csv"
    save_trajectory(path, tr.time, tr.formations)
    back = load_trajectory(path)
    np.testing.assert_array_equal(back.formations, tr.formations)
    with pytest.raises(InvalidTrajectoryError) as exc:
        parse_trajectory(text.splitlines(), n_robots=5)
    assert "expected 11" in exc.value.problem
    with pytest.raises(ScenarioError):
        load_trajectory(tmp_path / "missing.csv")
