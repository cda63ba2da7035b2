"""Files that cannot bomb or overwrite (issue 24): an output that is one of the
command's inputs is refused before any work (however it is spelled), outputs are written
atomically, and YAML alias bombs are refused in milliseconds by every loader."""

import json
import os
import time
from pathlib import Path

import pytest
import yaml

from taut.cli import main
from taut.errors import InvalidInputError, ScenarioError
from taut.io import MAX_YAML_VALUES, load_cdpr_model, parse_mapping, read_mapping, \
    write_text_atomic

ROOT = Path(__file__).parents[2]
CORRIDOR = ROOT / "examples" / "plan" / "paper_corridor.yaml"


def bomb(levels=9, width=9, top="lol"):
    lines = [f"a0: &a0 [{', '.join([top] * width)}]"]
    lines += [f"a{k}: &a{k} [{', '.join([f'*a{k - 1}'] * width)}]" for k in range(1, levels)]
    return "\n".join(lines) + "\n"


@pytest.fixture
def scenario_json(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "sc.json"
    path.write_text(json.dumps(yaml.safe_load(CORRIDOR.read_text())))
    return path


@pytest.mark.parametrize("spell", ["same", "dot", "parent", "symlink", "hardlink",
                                   "equals"])
def test_plan_output_over_its_scenario_is_refused(scenario_json, capsys, spell):
    before = scenario_json.read_bytes()
    out = {"same": "sc.json", "dot": "./sc.json",
           "parent": f"../{scenario_json.parent.name}/sc.json"}.get(spell, "other.json")
    if spell == "symlink":
        os.symlink("sc.json", "other.json")
    if spell == "hardlink":
        os.link("sc.json", "other.json")
    args = (["plan", "sc.json", "--out=sc.json"] if spell == "equals" else
            ["plan", "sc.json", "--out", out])
    t0 = time.perf_counter()
    assert main(args) == 2
    assert time.perf_counter() - t0 < 5            # refused before planning
    err = capsys.readouterr().err
    assert err.startswith("taut: error: --out: ") and "is also an input" in err
    assert scenario_json.read_bytes() == before


def test_cdpr_simulate_output_over_its_model_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    model = tmp_path / "m.json"
    model.write_text(json.dumps(_preset("fastkit")))
    before = model.read_bytes()
    assert main(["cdpr", "simulate", "m.json", "--waypoints", "-0.5,0,1.0; 0.5,0,1.0",
                 "--out", "m.json"]) == 2
    assert "is also an input" in capsys.readouterr().err
    assert model.read_bytes() == before


def _preset(name):
    from taut.io.cdpr_model import preset_path
    return read_mapping(preset_path(name))


def test_an_unrelated_existing_output_is_still_replaced(scenario_json, capsys):
    (scenario_json.parent / "old.json").write_text("{}")
    code = main(["plan", "sc.json", "--out", "old.json"])
    assert code in (0, 1)
    doc = json.loads((scenario_json.parent / "old.json").read_text())
    assert "success" in doc
    assert not list(scenario_json.parent.glob(".old.json.*"))      # no temporary left


def test_atomic_write_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch):
    import os

    target = tmp_path / "a.json"
    target.write_text("old")

    def full_disk(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", full_disk)         # fails after the temp file
    with pytest.raises(OSError):
        write_text_atomic(target, "new")
    monkeypatch.undo()
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]   # no temp file left
    with pytest.raises(InvalidInputError):
        write_text_atomic(target, 12345)                  # not text: refused, nothing written
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]
    write_text_atomic(target, "new")
    assert target.read_text() == "new"


# --- alias bombs -------------------------------------------------------------------------

def test_alias_bomb_is_refused_in_milliseconds(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(bomb())
    assert path.stat().st_size < 1000
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match="YAML aliases add more than"):
        read_mapping(path)
    assert time.perf_counter() - t0 < 0.5


def test_ordinary_aliases_still_work():
    assert parse_mapping("a: &x [1, 2]\nb: *x\n", "f.yaml") == {"a": [1, 2], "b": [1, 2]}
    # just under the limit is fine, just over is not
    width = 10
    ok = "a: &a [" + ", ".join(["1"] * width) + "]\nb: [" + ", ".join(
        ["*a"] * (MAX_YAML_VALUES // (width + 1))) + "]\n"
    assert len(parse_mapping(ok, "ok.yaml")["b"]) == MAX_YAML_VALUES // (width + 1)
    with pytest.raises(ScenarioError):
        parse_mapping("a: &a [" + ", ".join(["1"] * width) + "]\nb: [" + ", ".join(
            ["*a"] * (MAX_YAML_VALUES // width + 1)) + "]\n", "over.yaml")


def test_recursive_alias_is_refused():
    with pytest.raises(ScenarioError):
        parse_mapping("a: &x [1, *x]\n", "r.yaml")


@pytest.mark.parametrize("command", [
    ["fk", "{f}"], ["plan", "{f}"], ["cdpr", "tensions", "{f}", "--pose", "0", "0", "1"],
    ["app", "{f}", "--port", "0"],
])
def test_every_command_refuses_a_bomb_in_one_line(tmp_path, capsys, command):
    path = tmp_path / "bomb.yaml"
    path.write_text("name: x\n" + bomb())
    t0 = time.perf_counter()
    assert main([c.format(f=path) for c in command]) == 2
    assert time.perf_counter() - t0 < 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "YAML aliases add more than" in err


def test_sweep_file_bomb_is_refused(tmp_path, capsys):
    path = tmp_path / "sweep.yaml"
    path.write_text("task: fk_stability_map\nbase: x.yaml\nparameters: {scale: [1]}\n"
                    "options:\n  " + bomb().replace("\n", "\n  ").rstrip() + "\n")
    t0 = time.perf_counter()
    assert main(["sweep", "run", str(path), "--out", str(tmp_path / "o")]) == 2
    assert time.perf_counter() - t0 < 2
    assert "YAML aliases add more than" in capsys.readouterr().err


def test_too_large_file_is_refused(tmp_path, monkeypatch):
    from taut.io import files
    monkeypatch.setattr(files, "MAX_FILE_BYTES", 1000)
    path = tmp_path / "big.yaml"
    path.write_text("a: [" + "1, " * 1000 + "1]\n")
    with pytest.raises(ScenarioError, match="at most"):
        read_mapping(path)


def test_a_missing_extra_is_named_in_one_line(monkeypatch, capsys, scenario_json):
    """An optional dependency missing deep inside a command: one line naming the extra."""
    import sys

    from taut.cli import plan as plan_cli

    def needs_mujoco(*args, **kwargs):
        import mujoco  # noqa: F401
    monkeypatch.setitem(sys.modules, "mujoco", None)
    monkeypatch.setattr("taut.plan.planner.run_plan", needs_mujoco)
    assert plan_cli is not None
    assert main(["plan", "sc.json"]) == 2
    err = capsys.readouterr().err
    assert err == ("taut: error: mujoco: not installed; install taut[physics] "
                   "(pip install 'taut[physics]')\n")
