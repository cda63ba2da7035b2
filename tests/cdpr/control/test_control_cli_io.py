"""`taut cdpr simulate`, reference CSV files and the dynamics section of model files."""

import json

import numpy as np
import pytest

from taut.cdpr import pick_and_place, with_stabilisers
from taut.cli import main
from taut.io.cdpr_dynamics import dynamics_from_mapping, load_cdpr_dynamics
from taut.io.cdpr_reference import read_reference_csv, write_reference_csv
from taut.errors import InvalidInputError, InvalidModelError, ScenarioError

WP = "-0.3,0,1.0; 0.3,0,1.0"


def _cli(capsys, *args):
    code = main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_simulate_writes_the_result_fields(capsys, tmp_path):
    out = tmp_path / "run.json"
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--waypoints", WP, "--controller", "torque", "--dwell", "0.1",
                           "--out", str(out))
    assert code == 0, err
    assert "tracking error" in text and "written to" in text
    data = json.loads(out.read_text())
    for key in ("times", "poses", "reference", "tracking_error", "tensions", "motor_torques",
                "tipping_margin", "events", "success", "status", "message"):
        assert key in data
    assert data["status"] == "ok" and len(data["poses"][0]) == 6
    # encoder sensing, rotors that stick (0.02 N m breakaway) and the routed cable length's
    # compliance: ~1.2 mm without model errors (0.44 mm with neither)
    assert max(data["tracking_error"]) < 2e-3


def test_cli_velocity_control_with_exit_errors_answers_no(capsys):
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--waypoints", WP, "--controller", "velocity", "--exit-error",
                           "0.005", "--dwell", "0.1")
    assert code == 1
    assert "slack" in text or "over_tension" in text
    assert len(err.strip().splitlines()) == 1 and err.startswith("taut: infeasible:")


@pytest.mark.parametrize("args, field", [
    (["--waypoints", WP, "--controller", "pid"], "--controller"),
    (["--waypoints", "0,0,1.0; 9,0,1.0"], "waypoints[1]"),
    (["--waypoints", "0,0,1.0"], "--waypoints"),
    (["--waypoints", "0,0,nan; 1,0,1"], "--waypoints"),
    (["--waypoints", WP, "--speed", "0"], "speed"),
    (["--waypoints", WP, "--control-rate", "20"], "control_rate"),
    (["--waypoints", WP, "--exit-error", "-1"], "--exit-error"),
    (["--waypoints", WP, "--out", "/proc/no/x.json"], "--out"),
    (["--waypoints", WP, "--out", "x.txt"], "--out"),
    (["--waypoints", WP, "--animate", "x.png"], "--animate"),
    ([], "--waypoints"),
])
def test_cli_bad_input_is_one_line_exit_2(capsys, args, field):
    code, _, err = _cli(capsys, "cdpr", "simulate", "fastkit", *args)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"taut: error: {field}")


def test_cli_json_flag_prints_valid_json(capsys):
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--waypoints", WP, "--controller", "torque", "--dwell", "0.1",
                           "--json")
    assert code == 0, err
    data = json.loads(text)                       # strict: no NaN / Infinity
    assert data["status"] == "ok" and data["success"] is True


def test_reference_csv_round_trip(fastkit, tmp_path):
    robot = with_stabilisers(fastkit)
    ref = pick_and_place(robot, [[-0.5, 0, 1.0], [0.5, 0.1, 1.2]], rate=200.0)
    path = tmp_path / "ref.csv"
    write_reference_csv(ref, path)
    back = read_reference_csv(robot, path)
    assert np.allclose(back.poses, ref.poses, atol=1e-8)
    assert np.abs(back.velocities[5:-5] - ref.velocities[5:-5]).max() < 2e-3   # FD vs exact


def test_reference_csv_errors(fastkit, tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("t,x,y,z\n0,0,0,1\n")
    with pytest.raises(ScenarioError, match="header"):
        read_reference_csv(fastkit, p)
    p.write_text("time,x,y,z,roll,pitch,yaw\n0,0,0,1,0,0,0\n1,0,0,1,0,0,0\n1,0,0,1,0,0,0\n")
    with pytest.raises(InvalidInputError, match="increasing"):
        read_reference_csv(fastkit, p)
    p.write_text("time,x,y,z,roll,pitch,yaw\n0,0,0,1,0,0,0\n0.01,500,0,1,0,0,0\n"
                 "0.02,0,0,1,0,0,0\n")
    with pytest.raises(Exception, match="frame box|speed"):
        read_reference_csv(fastkit, p)


def test_dynamics_section_of_the_presets():
    d = load_cdpr_dynamics("fastkit")
    # FASTKIT Table 1: 0.08 m drum, 5:1, 70 %, 0.6 N m holds 45 N with margin; 2 m/s
    assert d.drum_diameter == 0.08 and d.gear_ratio == 5.0 and d.efficiency == 0.7
    assert d.max_cable_tension >= 45.0
    assert d.max_cable_speed == pytest.approx(2.0)
    assert load_cdpr_dynamics("ipanema").cable_stiffness == 2e5
    # rated / peak torque and the routing per cable (exit height - 0.1 m, cable order)
    assert d.rated_torque == 0.6 and d.peak_torque == 1.8 and d.peak_duration == 1.0
    assert d.routing(8).tolist() == [2.3, 2.3, 2.15, 2.15, 2.3, 2.3, 2.15, 2.15]
    with pytest.raises(InvalidModelError, match="dynamics.routing_length: has 8 values"):
        d.routing(4)
    with pytest.raises(InvalidModelError, match="dynamics.routing_length"):
        dynamics_from_mapping({"routing_length": [1.0, -0.5]})
    with pytest.raises(InvalidModelError, match="dynamics.peak_torque"):
        dynamics_from_mapping({"rated_torque": 1.0, "peak_torque": 0.5})
    with pytest.raises(ScenarioError, match="dynamics.routing_length"):
        dynamics_from_mapping({"routing_length": "long"})
    with pytest.raises(InvalidModelError, match="dynamics.cable_stiffness"):
        dynamics_from_mapping({"cable_stiffness": 0.0})
    with pytest.raises(ScenarioError, match="dynamics.typo"):
        dynamics_from_mapping({"typo": 1.0})


def test_cli_simulate_from_a_reference_csv(capsys, tmp_path, fastkit):
    ref = pick_and_place(with_stabilisers(fastkit), [[-0.2, 0, 0.9], [0.2, 0, 0.9]], dwell=0.1,
                         rate=100.0)
    path = tmp_path / "ref.csv"
    write_reference_csv(ref, path)
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--reference", str(path), "--controller", "torque")
    assert code == 0, err
    assert "torque control over" in text
    code, _, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--reference",
                        str(tmp_path / "missing.csv"))
    assert code == 2 and err.startswith("taut: error:")


def test_cli_tension_feedback_and_ideal_pose_options(capsys):
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--waypoints", WP, "--controller", "velocity", "--dwell", "0.1",
                           "--tension-gain", "200", "--exit-error", "0.005", "--json")
    data = json.loads(text)
    assert data["controller"]["tension_gain"] == 200.0
    lib = simulate_lib("velocity", tension_gain=200.0)
    assert max(data["tracking_error"]) == pytest.approx(lib.tracking_error.max(), rel=1e-9)
    code, text, err = _cli(capsys, "cdpr", "simulate", "fastkit", "--stabilisers",
                           "--waypoints", WP, "--controller", "torque", "--tension-gain", "1")
    assert code == 2 and "--tension-gain" in err and len(err.strip().splitlines()) == 1


def simulate_lib(name, **kw):
    from taut.cdpr import CONTROLLERS, ModelErrors, pick_and_place, simulate, with_stabilisers
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    pts = [[float(v) for v in p.split(",")] for p in WP.split(";")]
    ref = pick_and_place(robot, pts, dwell=0.1)
    # the CLI simulates the preset's dynamics section (per-cable routing lengths)
    return simulate(robot, ref, CONTROLLERS[name](**kw), model_errors=ModelErrors(exit_offset=0.005),
                    dynamics=load_cdpr_dynamics("fastkit"))


def test_reference_csv_errors_name_the_line_of_the_file(fastkit, tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("# a reference\n# written by hand\ntime,x,y,z,roll,pitch,yaw\n"
                 "0,0,0,1,0,0,0\n\n# a comment between rows\n1,0,0,1,0,x,0\n")
    with pytest.raises(ScenarioError) as err:
        read_reference_csv(fastkit, p)
    assert err.value.field == "reference[7]" and "line 7" in err.value.problem
    p.write_text("time,x,y,z,roll,pitch,yaw\n# note\n0,0,0,1,0,0\n")
    with pytest.raises(ScenarioError) as err:
        read_reference_csv(fastkit, p)
    assert err.value.field == "reference[3]" and "got 6" in err.value.problem
    p.write_text("# only a comment\n\n")
    with pytest.raises(ScenarioError, match="empty"):
        read_reference_csv(fastkit, p)
