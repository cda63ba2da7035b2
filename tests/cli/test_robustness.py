"""Regression tests of issue 11: output paths checked before the work, no silent wrong
answers, accepted numeric ranges, one exit-code table, one box order, no warning leaks,
fast and complete `--help`."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import typer
import yaml

import taut.cli as cli
from taut.cli import main
from cli_calls import run
from taut.errors import InvalidInputError, TautError
from progress_lines import without_progress

ROOT = Path(__file__).parents[2]
EX1 = ROOT / "examples" / "sheet" / "example1.yaml"


def one_error_line(err, *words):
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("taut: error: "), err
    for w in words:
        assert w in lines[0], err


# --- 1. output paths ---------------------------------------------------------------------

@pytest.mark.parametrize("target, words", [
    ("", ["empty file name"]), ("noext", ["no file extension"]),
    ("fig.jpg", ["unsupported extension '.jpg'"]), (".png", ["no file extension"]),
    ("{tmp}", ["is a directory"]), ("{tmp}/f.txt/x.png", ["is not a directory"]),
    ("/proc/none/x.png", ["cannot write"]),
])
def test_bad_output_path_refused_before_the_work(capsys, monkeypatch, tmp_path, target, words):
    (tmp_path / "f.txt").write_text("x")
    import taut.sheet
    monkeypatch.setattr(taut.sheet, "forward_kinematics",
                        lambda *a, **k: pytest.fail("FK ran before the path was checked"))
    code, out, err = run(capsys, "fk", EX1, "--plot", target.format(tmp=tmp_path))
    assert code == 2 and out == ""
    one_error_line(err, "--plot", *words)


def test_output_written_exactly_where_asked(capsys, tmp_path):
    target = tmp_path / "new" / "dir" / "fig.pdf"
    code, out, _ = run(capsys, "fk", EX1, "--plot", target)
    assert code == 0 and f"figure written to {target}" in out
    assert target.read_bytes()[:4] == b"%PDF"
    assert sorted(p.name for p in target.parent.iterdir()) == ["fig.pdf"]


def test_probe_leaves_no_file_behind_on_error(capsys, tmp_path):
    code, _, _ = run(capsys, "fk", tmp_path / "missing.yaml", "--plot", tmp_path / "f.png")
    assert code == 2 and not (tmp_path / "f.png").exists()


# --- 2. silent wrong answers ---------------------------------------------------------------

def _scenario(tmp_path, **changes):
    doc = yaml.safe_load(EX1.read_text())
    doc.update(changes)
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(doc))
    return p


def test_fk_without_equilibrium_says_why_and_exits_1(capsys, tmp_path):
    """Lowering the holding points lowers every state by the same amount (the depth below
    them does not depend on z_r): at z_r = 100 mm Example 1's three states (136 mm high at
    z_r = 800) hang 564 mm below the floor, and the message says exactly that."""
    code, out, err = run(capsys, "fk", _scenario(tmp_path, hold_height=100), "--json")
    assert code == 1 and without_progress(err) == ""
    doc = json.loads(out)
    assert doc["equilibria"] == [] and "3 state(s) discarded" in doc["message"]
    high = json.loads(run(capsys, "fk", EX1, "--json")[1])["equilibria"]
    for e in high:
        label = "{" + ",".join(str(i + 1) for i in e["taut"]) + "}"
        assert f"{label} at z_o = {e['object'][2] - 700:.4g}" in doc["message"]
    code, out, _ = run(capsys, "fk", _scenario(tmp_path, hold_height=100))
    assert code == 1 and "below the floor" in out


@pytest.mark.parametrize("text, field", [
    ("hold_height: true\n", "hold_height"),
    ("mass: false\n", "mass"),
    ("hold_height: 900\n", "hold_height"),           # a second hold_height
])
def test_yaml_booleans_and_duplicate_keys_rejected(capsys, tmp_path, text, field):
    src = EX1.read_text()
    if text.startswith("hold_height: true"):
        src = src.replace("hold_height: 800", "hold_height: true")
    elif text.startswith("mass"):
        src += "\n" + text
    else:
        src += "\n" + text
    p = tmp_path / "s.yaml"
    p.write_text(src)
    code, _, err = run(capsys, "fk", p)
    assert code == 2
    one_error_line(err, field)


def test_json_duplicate_keys_and_booleans_in_other_loaders(capsys, tmp_path):
    from taut.io import load_cdpr_model, load_plan_scenario
    plan = yaml.safe_load((ROOT / "examples" / "plan" / "paper_corridor.yaml").read_text())
    plan["team"]["speed"] = True
    p = tmp_path / "plan.yaml"
    p.write_text(yaml.safe_dump(plan))
    with pytest.raises(TautError, match="boolean") as exc:
        load_plan_scenario(p)
    assert exc.value.field == "team.speed"
    j = tmp_path / "m.json"
    j.write_text('{"name": "a", "name": "b"}')
    with pytest.raises(TautError, match="duplicate key"):
        load_cdpr_model(j)


def test_huge_mass_is_refused_and_json_is_always_valid(capsys):
    code, _, err = run(capsys, "fk", EX1, "--mass", "1e308", "--json")
    assert code == 2
    one_error_line(err, "--mass", "1e+06 kg")
    code, out, _ = run(capsys, "fk", EX1, "--mass", "1e6", "--json")
    assert code == 0
    doc = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert all(np.isfinite(e["tensions"]).all() for e in doc["equilibria"] if e["tensions"])


def test_to_json_never_writes_infinity():
    from taut.io.serialize import to_json
    text = to_json({"a": float("inf"), "b": [np.float64("nan"), np.int64(3)],
                    "c": np.array([1.0, -np.inf])})
    assert json.loads(text) == {"a": None, "b": [None, 3], "c": [1.0, None]}


@pytest.mark.parametrize("argv, field", [
    (["cdpr", "twist-set", "fastkit", "--pose", "0", "0", "1", "--cable-speed", "1e308"],
     "--cable-speed"),
    (["cdpr", "tensions", "fastkit", "--pose", "1e308", "0", "1"], "pose"),
    (["ik", str(EX1), "--object", "1e308", "0", "300"], "--object"),
])
def test_overflowing_numbers_are_refused(capsys, argv, field):
    code, _, err = run(capsys, *argv)
    assert code == 2
    one_error_line(err, field, "accepted range")


def test_huge_tension_limit_in_a_model_file_is_refused(capsys, tmp_path):
    data = yaml.safe_load((ROOT / "src" / "taut" / "data" / "fastkit.yaml").read_text())
    cables = data["cables"]
    first = cables[0] if isinstance(cables, list) else next(iter(cables.values()))
    key = "t_max" if "t_max" in first else next(k for k in first if "max" in k)
    first[key] = 1e308
    p = tmp_path / "big.yaml"
    p.write_text(yaml.safe_dump(data))
    code, _, err = run(capsys, "cdpr", "tensions", p, "--pose", "0", "0", "1")
    assert code == 2 and "exceeds the accepted range" in err


# --- 3. missing checks and bounded work ---------------------------------------------------

@pytest.mark.parametrize("argv, words", [
    (["cdpr", "workspace", "fastkit", "--box", "1", "-1", "0", "0", "0.2", "1"],
     ["box", "xmax -1 < xmin 1"]),
    (["cdpr", "deploy", "fastkit", "--workspace", "-1", "1", "0", "0.1", "-1", "-0.2"],
     ["workspace", "below the floor"]),
    (["cdpr", "deploy", "fastkit", "--workspace", "-1e308", "1", "0", "0.1", "0.2", "1"],
     ["workspace", "accepted range"]),
    (["cdpr", "deploy", "fastkit", "--workspace", "-1", "1", "0", "0.1", "0.2", "1",
      "--maxiter", "100000"], ["maxiter", "at most"]),
    (["cdpr", "workspace", "fastkit", "--grid", "1000", "1000", "10"], ["grid", "exceeds"]),
])
def test_missing_checks_fail_fast(capsys, argv, words):
    code, _, err = run(capsys, *argv)
    assert code == 2
    one_error_line(err, *words)


def test_one_box_order_for_workspace_and_deploy(capsys):
    """`workspace --box` and `deploy --workspace` read the same six numbers the same way."""
    from taut._validate import as_box
    code, out, _ = run(capsys, "cdpr", "workspace", "fastkit", "--box", "-1", "1", "-0.05",
                       "0.05", "0.2", "1", "--grid", "3", "1", "2", "--json")
    assert code == 0
    assert json.loads(out)["box"] == as_box([-1, 1, -0.05, 0.05, 0.2, 1], "box").tolist() \
        == [[-1.0, -0.05, 0.2], [1.0, 0.05, 1.0]]


def test_subsets_size_guard(capsys, tmp_path):
    n = 41
    t = 2 * np.pi * np.arange(n) / n
    sheet = np.column_stack([np.cos(t), np.sin(t)]) * 1000
    p = tmp_path / "big.yaml"
    p.write_text(yaml.safe_dump({"hold_height": 1000, "sheet": sheet.tolist(),
                                 "formation": (0.8 * sheet).tolist()}))
    code, _, err = run(capsys, "fk", p, "--method", "subsets")
    assert code == 2
    one_error_line(err, "sheet", "at most 40")


def test_planning_team_size_is_bounded(tmp_path):
    from taut.io import load_plan_scenario
    doc = yaml.safe_load((ROOT / "examples" / "plan" / "paper_corridor.yaml").read_text())
    doc["team"]["regular"]["n"] = 1_000_000_000
    p = tmp_path / "p.yaml"
    p.write_text(yaml.safe_dump(doc))
    with pytest.raises(TautError, match="1000"):
        load_plan_scenario(p)


# --- 4. progress ---------------------------------------------------------------------------

def test_progress_lines_when_not_a_terminal(capsys, monkeypatch):
    import time
    from taut.cli import _progress
    monkeypatch.setattr(_progress, "FIRST_NOTICE_S", 0.05)
    monkeypatch.setattr(_progress, "NOTICE_EVERY_S", 0.05)
    with _progress.working("demo") as update:
        update(3, 10)
        time.sleep(0.3)
    err = capsys.readouterr().err
    assert err.startswith("taut: demo: working, ") and "(3/10)" in err
    with _progress.working("quick"):
        pass
    assert capsys.readouterr().err == ""                      # short runs stay silent


@pytest.mark.parametrize("value", ["soon", "-1", "nan", "inf", "1e308"])
def test_a_bad_progress_delay_is_one_line(capsys, monkeypatch, value):
    """TAUT_PROGRESS_AFTER_S is an input like any other: refused in one line, exit 2."""
    monkeypatch.setenv("TAUT_PROGRESS_AFTER_S", value)
    assert main(["fk", str(ROOT / "examples/sheet/example1.yaml")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("taut: error: TAUT_PROGRESS_AFTER_S: ")


def test_the_progress_delay_sets_the_first_line(capsys, monkeypatch):
    import time
    from taut.cli import _progress
    monkeypatch.setenv("TAUT_PROGRESS_AFTER_S", "0")
    with _progress.working("demo"):
        time.sleep(0.2)
    assert capsys.readouterr().err.startswith("taut: demo: working, 0 s")


# --- 5. warnings never leak ----------------------------------------------------------------

def test_numeric_warnings_do_not_leak_before_the_error(capsys, monkeypatch):
    import taut.sheet

    def noisy(*a, **k):
        np.log(np.zeros(1))                                   # RuntimeWarning
        warnings.warn("overflow", RuntimeWarning)
        raise InvalidInputError("formation", "made up for the test")

    monkeypatch.setattr(taut.sheet, "forward_kinematics", noisy)
    code, out, err = run(capsys, "fk", EX1)
    assert code == 2 and out == ""
    one_error_line(err, "formation: made up for the test")


# --- 6. exit codes -------------------------------------------------------------------------

def test_tensions_infeasible_exits_1(capsys):
    code, out, _ = run(capsys, "cdpr", "tensions", "fastkit", "--pose", "0", "0", "2.35",
                       "--json")
    assert code == 1 and json.loads(out)["feasible"] is False
    code, out, _ = run(capsys, "cdpr", "tensions", "fastkit", "--pose", "0", "0", "0.6")
    assert code == 0 and "feasible: yes" in out
    code, out, _ = run(capsys, "cdpr", "tensions", "fastkit", "--pose", "0", "0", "1.2")
    assert code == 1 and "tip over" in out.splitlines()[-1]         # the bases tip


def test_exit_codes_documented_in_help_and_readme(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0
    text = " ".join(out.split())
    assert "1 a valid question answered no" in text and "2 invalid input" in text
    readme = (ROOT / "README.md").read_text()
    assert "| 1 | a valid question answered \"no\"" in readme


# --- 8. help and imports -------------------------------------------------------------------

def _commands(group, prefix=()):
    for name, cmd in getattr(group, "commands", {}).items():
        if getattr(cmd, "commands", None):                    # a sub-group (cdpr)
            yield from _commands(cmd, prefix + (name,))
        else:
            yield prefix + (name,), cmd


def test_every_option_and_argument_has_help():
    root = typer.main.get_command(cli.app)
    missing = []
    commands = list(_commands(root))
    assert {" ".join(p) for p, _ in commands} >= {"fk", "ik", "simulate", "plan",
                                                   "cdpr tensions", "cdpr deploy"}
    for path, cmd in commands:
        assert cmd.help, path
        for p in cmd.params:
            if not (getattr(p, "help", None) or "").strip():
                missing.append(f"{' '.join(path)} {p.name}")
    assert missing == []


def test_help_imports_no_solver_library():
    """`taut --help` must not import scipy, shapely or matplotlib (they cost ~1 s)."""
    code = ("import sys, taut.cli; taut.cli.main(['--help']); "
            "bad = [m for m in ('scipy', 'shapely', 'matplotlib', 'pydantic') "
            "if m in sys.modules]; print(bad)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


def test_no_shell_completion_offered(capsys):
    code, out, _ = run(capsys, "--help")
    assert "--install-completion" not in out and "--show-completion" not in out


def test_plan_baseline_plot_says_why_not(capsys, tmp_path):
    target = tmp_path / "x.png"
    code, out, err = run(capsys, "plan", ROOT / "examples" / "plan" / "paper_corridor.yaml",
                         "--disc-baseline", "--plot", target)
    assert code == 1 and out.startswith("no plan (no_route): ")
    assert err == f"taut: --plot: {target} not written: there is no plan to draw\n"
    assert not target.exists()


def test_plan_json_is_a_flag_like_every_other(capsys, tmp_path):
    """`plan --json` prints JSON on stdout (like fk, ik, cdpr ...); --out writes a file."""
    out_file = tmp_path / "p.json"
    code, out, _ = run(capsys, "plan", ROOT / "examples" / "plan" / "paper_corridor.yaml",
                       "--disc-baseline", "--json", "--out", out_file)
    assert code == 1
    doc = json.loads(out)
    assert doc == json.loads(out_file.read_text())
    assert doc["success"] is False and doc["status"] == "no_route"
    assert doc["message"] and "reason" not in doc
