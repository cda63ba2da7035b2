"""Issue 11 ("every command survives every input"), re-walked item by item against main.
Each row is reproduced by the test named in the last column (``-`` where another module
holds the regression test).

=====  ======================================================  =========================
item   quoted case                                             test
=====  ======================================================  =========================
1      ``--plot noext`` / ``--plot ''`` refused before work    test_output_names_refused
2      ``hold_height: true``, duplicate keys                   test_yaml_booleans_and_dups
2      ``--mass 1e308`` (no ``inf`` tensions, no ``Infinity``)  test_huge_numbers_refused
2      ``twist-set --cable-speed 1e308``                       test_huge_numbers_refused
2      closed form at ``t_max = 1e308``                        test_huge_tension_limit
2      coordinates of 1e308 ("repeats vertex 0")               test_api_quoted_cases
2      ``wrench_feasible(..., chunk=-1)``                      test_api_quoted_cases
3      ``cdpr workspace --box`` min > max                      test_box_min_above_max
3      ``cdpr deploy --workspace`` below the floor, +-1e308    test_deploy_workspace_checks
3      ``fk --method subsets`` with 500 robots                 test_subsets_size_guard
3      planning team ``n: 40`` / ``n: 1e9``                    - (engineer "plan")
4      progress of exhaustive FK, plan, deploy, twist-set      - (tests/cli/test_robustness.py)
5      no numpy warning before the error line                  test_huge_numbers_refused
6      exit codes 0/1/2 in ``--help``                          test_help_texts
7      ``Sheet.regular(10**7, 1)``, ``generate_scenario(0, 0)``  test_api_quoted_cases
7      ``forward_kinematics_batch(team, empty (0,4,2))``       test_api_quoted_cases
7      None in place of a model (twist_capacities, ...)        test_none_in_place_of_model
8      ``ik --help`` formation text, every option has help     test_help_texts
8      ``plan --json`` a flag like every other ``--json``      test_plan_json_is_a_flag
8      shell completion works or is not offered                test_help_texts
9      figure legends/units                                    - (tests/cli/test_figures.py)
10     standing CLI and API fuzz                               - (test_fuzz_cli.py,
                                                                  test_api_fuzz*.py)
(4)    ``dynamics:`` key set to null says "must be a number"   test_null_dynamics_value
=====  ======================================================  =========================
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taut.cli import main
from taut.errors import TautError

ROOT = Path(__file__).parents[2]
SHEET = str(ROOT / "examples" / "sheet" / "example1.yaml")
POSE = ["--pose", "0", "0", "1"]


def _click_root():
    import typer
    from taut.cli import app
    return typer.main.get_command(app)


def _error(capsys, argv: list[str]) -> str:
    """Run; assert the one-line error contract; return the line."""
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 2, (argv, code, out, err)
    assert "Traceback" not in err and "Warning" not in err, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("taut: error: "), err
    return lines[0]


@pytest.mark.parametrize("name", ["noext", "", ".png"])
def test_output_names_refused(capsys, tmp_path, name):
    line = _error(capsys, ["fk", SHEET, "--plot", str(tmp_path / name) if name else ""])
    assert "--plot" in line
    assert not list(tmp_path.iterdir())                   # nothing written


def test_yaml_booleans_and_dups(capsys, tmp_path):
    text = Path(SHEET).read_text()
    p = tmp_path / "bool.yaml"
    p.write_text("\n".join("hold_height: true" if ln.startswith("hold_height") else ln
                           for ln in text.splitlines()) + "\n")
    assert "hold_height" in _error(capsys, ["fk", str(p)])
    d = tmp_path / "dup.yaml"
    d.write_text(text + "\nhold_height: 900\n")
    assert "hold_height" in _error(capsys, ["fk", str(d)])


@pytest.mark.parametrize("argv, field", [
    (["fk", SHEET, "--mass", "1e308"], "mass"),
    (["cdpr", "twist-set", "fastkit", *POSE, "--cable-speed", "1e308"], "cable"),
])
def test_huge_numbers_refused(capsys, argv, field):
    assert field in _error(capsys, argv)


@pytest.mark.parametrize("option, value", [("--cable-speed", "1e308"), ("--cable-speed", "0"),
                                           ("--base-speed", "1e308"), ("--yaw-rate", "-1")])
def test_twist_set_speed_errors_name_the_option(capsys, option, value):
    """The refused speed limit is named by the option the user typed (it used to say
    ``limits.cable`` / ``limits.base``, the model's field)."""
    err = _error(capsys, ["cdpr", "twist-set", "fastkit", *POSE, option, value])
    assert err.startswith(f"taut: error: {option}: "), err
    assert "limits." not in err


def test_huge_tension_limit():
    """t_max = 1e308 is outside the accepted range (not "infeasible" by overflow)."""
    from dataclasses import replace
    from taut.io import load_cdpr_model
    robot = load_cdpr_model("fastkit")
    cables = (replace(robot.cables[0], t_max=1e308),) + robot.cables[1:]
    with pytest.raises(TautError) as exc:
        replace(robot, cables=cables)
    assert "t_max" in exc.value.field


def test_box_min_above_max(capsys):
    line = _error(capsys, ["cdpr", "workspace", "fastkit", "--box", "1", "-1", "0", "0",
                           "0.2", "1"])
    assert "box" in line and "xmax -1 < xmin 1" in line


@pytest.mark.parametrize("box", [["-1", "1", "0", "0.1", "-1", "-0.2"],
                                 ["-1e308", "1", "0", "0.1", "0.2", "1"],
                                 ["-1", "1e308", "0", "0.1", "0.2", "1"]])
def test_deploy_workspace_checks(capsys, box):
    assert "workspace" in _error(capsys, ["cdpr", "deploy", "fastkit", "--workspace", *box])


def test_subsets_size_guard(capsys, tmp_path):
    n = 500
    ang = 2 * np.pi * np.arange(n) / n
    verts = np.column_stack([np.cos(ang), np.sin(ang)]) * 1000
    p = tmp_path / "big.yaml"
    p.write_text(f"sheet: {verts.round(6).tolist()}\nhold_height: 900\n"
                 f"formation: {(0.5 * verts).round(6).tolist()}\n")
    line = _error(capsys, ["fk", str(p), "--method", "subsets"])
    assert "robots" in line or "method" in line or "sheet" in line


def test_api_quoted_cases():
    from taut.cdpr import wrench_feasible
    from taut.io import load_cdpr_model
    from taut.plan import generate_scenario
    from taut.sheet import Sheet, SheetTeam, forward_kinematics_batch
    team = SheetTeam(Sheet.regular(4, 1.0), 1.0)
    for call, field in [
            (lambda: Sheet.regular(10**7, 1), "n"),
            (lambda: generate_scenario(0, 0), "n_robots"),
            (lambda: forward_kinematics_batch(team, np.empty((0, 4, 2))), "formations"),
            (lambda: wrench_feasible(load_cdpr_model("fastkit"), [[0, 0, 1]], chunk=-1),
             "chunk"),
            (lambda: Sheet([[1e308, 0], [0, 1], [1, 1]]), "sheet")]:
        with pytest.raises(TautError) as exc:
            call()
        assert exc.value.field == field


@pytest.mark.parametrize("name", ["twist_capacities", "available_twist_set",
                                  "resolve_redundancy", "plan_deployment",
                                  "distribute_tensions", "first_order_model"])
def test_none_in_place_of_model(name):
    import taut.cdpr as cdpr
    args = {"resolve_redundancy": (None, [0, 0, 1], np.zeros(6)),
            "plan_deployment": (None, [-0.5, 0.5, 0, 0, 0.5, 1.0])}.get(name, (None, [0, 0, 1]))
    with pytest.raises(TautError) as exc:
        getattr(cdpr, name)(*args)
    assert exc.value.field == "robot" and "CableRobot" in exc.value.problem


def test_null_dynamics_value():
    from taut.io.cdpr_dynamics import dynamics_from_mapping
    for key in ("cable_stiffness", "efficiency", "drum_diameter"):
        with pytest.raises(TautError) as exc:
            dynamics_from_mapping({key: None})
        assert exc.value.field == f"dynamics.{key}"
        assert "must be a number" in exc.value.problem and "NaN" not in exc.value.problem


def test_help_texts(capsys):
    """Every option of every command has help text; ``ik --help`` does not claim the
    formation is ignored; the exit-code table is in ``taut --help``; no completion option
    is offered that does not work."""
    cli = _click_root()
    assert main(["--help"]) == 0
    top = capsys.readouterr().out
    assert "Exit codes" in top and "completion" not in top.lower()

    def walk(cmd, path: str):
        yield path, cmd
        for name, sub in getattr(cmd, "commands", {}).items():
            yield from walk(sub, f"{path} {name}")
    commands = list(walk(cli, "taut"))
    options = [(path, p) for path, cmd in commands for p in cmd.params
               if p.param_type_name == "option"]
    assert len(commands) > 10 and len(options) > 50       # the walk reached the tree
    missing = [f"{path} {p.opts[0]}" for path, p in options
               if not p.help and p.opts[0] != "--version"]
    assert missing == []
    assert main(["ik", "--help"]) == 0
    assert "ignored" not in capsys.readouterr().out


def test_plan_json_is_a_flag():
    plan = _click_root().commands["plan"]
    opt = next(p for p in plan.params if "--json" in p.opts)
    assert opt.param_type_name == "option" and opt.is_flag
