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
#: Options some commands require (a platform pose, waypoints, a workspace box).
POSE = ["--pose", "0", "0", "1"]
WAYPOINTS = ["--waypoints", "-0.5,0,1.0; 0.5,0,1.0"]
BOX = ["--workspace", "-0.5", "0.5", "-0.1", "0.1", "0.5", "1.0"]


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


def _command_id(words):
    """``["cdpr", "simulate", "{model}", ..., "--plot", "{out}.png"]`` -> ``"cdpr simulate
    --plot"``."""
    head = words[:next(k for k, w in enumerate(words) if w.startswith("{"))]
    return " ".join(head + [words[words.index(next(w for w in words
                                                   if w.startswith("{out}"))) - 1]])


@pytest.mark.parametrize("command, source", [
    (["fk", "{sheet}", "--plot", "{out}.png"], "sheet"),
    (["simulate", "{sheet}", "--trajectory", "{csv}", "--plot", "{out}.png"], "sheet"),
    (["simulate", "{sheet}", "--trajectory", "{csv}", "--plot", "{out}.png"], "csv"),
    (["plan", "{plan}", "--out", "{out}.json"], "plan"),
    (["plan", "{plan}", "--plot", "{out}.png"], "plan"),
    (["plan", "{plan}", "--animate", "{out}.gif"], "plan"),
    (["physics", "{sheet}", "--plot", "{out}.png"], "sheet"),
    (["physics", "{sheet}", "--video", "{out}.gif"], "sheet"),
    (["cdpr", "wrench-set", "{model}", *POSE, "--plot", "{out}.png"], "model"),
    (["cdpr", "workspace", "{model}", "--plot", "{out}.png"], "model"),
    (["cdpr", "twist-set", "{model}", *POSE, "--plot", "{out}.png"], "model"),
    (["cdpr", "deploy", "{model}", *BOX, "--plot", "{out}.png"], "model"),
    (["cdpr", "simulate", "{model}", *WAYPOINTS, "--out", "{out}.json"], "model"),
    (["cdpr", "simulate", "{model}", *WAYPOINTS, "--plot", "{out}.png"], "model"),
    (["cdpr", "simulate", "{model}", *WAYPOINTS, "--animate", "{out}.gif"], "model"),
    (["cdpr", "simulate", "{model}", "--reference", "{ref}", "--out", "{out}.json"], "ref"),
], ids=lambda v: _command_id(v) if isinstance(v, list) else v)
def test_no_command_writes_over_one_of_its_inputs(tmp_path, monkeypatch, capsys, command,
                                                  source):
    """Every file a command writes (--out, --plot, --animate, --video), given as another
    name (a hard link) of one of the command's inputs, is refused in one line and the
    input is left as it was."""
    monkeypatch.chdir(tmp_path)
    files = {"sheet": tmp_path / "sheet.yaml", "plan": tmp_path / "plan.yaml",
             "model": tmp_path / "model.yaml", "csv": tmp_path / "traj.csv",
             "ref": tmp_path / "ref.csv"}
    files["sheet"].write_text((ROOT / "examples" / "sheet" / "example1.yaml").read_text())
    files["plan"].write_text(CORRIDOR.read_text())
    files["model"].write_text(yaml.safe_dump(_preset("fastkit")))
    files["csv"].write_text("time,x1,y1,x2,y2,x3,y3,x4,y4\n"
                            "0,210,120,800,40,900,550,440,720\n"
                            "1,215,120,800,40,900,550,440,720\n")
    files["ref"].write_text("time,x,y,z,roll,pitch,yaw\n0,0,0,1,0,0,0\n1,0,0,1,0,0,0\n"
                            "2,0,0,1,0,0,0\n")
    suffix = next(w for w in command if w.startswith("{out}"))[len("{out}"):]
    out = tmp_path / f"out{suffix}"
    os.link(files[source], out)
    before = files[source].read_bytes()
    args = [w.format(out="out", **files) for w in command]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"'{out.name}' is also an input" in err, err
    assert files[source].read_bytes() == before


def _preset(name):
    from taut.io.cdpr_model import preset_path
    return read_mapping(preset_path(name))


@pytest.mark.parametrize("spell", ["plan.json", "./plan.json"])
def test_two_outputs_of_one_command_cannot_share_a_file(scenario_json, capsys, spell):
    """``--out`` and ``--trajectories`` naming one new file would have the second write
    replace the first: refused before planning, naming the option and the other one."""
    t0 = time.perf_counter()
    assert main(["plan", "sc.json", "--out", "plan.json", "--trajectories", spell,
                 "--max-speed", "0.2", "--max-accel", "0.5",
                 "--max-yaw-rate", "1"]) == 2
    assert time.perf_counter() - t0 < 5
    err = capsys.readouterr().err
    assert err == (f"taut: error: --trajectories: {str(Path(spell))!r} is also the file of --out; "
                   "give each output its own file\n")
    assert not (scenario_json.parent / "plan.json").exists()


def test_a_bad_trajectories_file_is_named_once(scenario_json, capsys):
    assert main(["plan", "sc.json", "--trajectories", "t.txt", "--max-speed", "0.2",
                 "--max-accel", "0.5", "--max-yaw-rate", "1"]) == 2
    assert capsys.readouterr().err.startswith("taut: error: --trajectories: unsupported "
                                              "extension '.txt'")


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
    ["fk", "{f}"], ["ik", "{f}", "--object", "0", "0", "1"],
    ["simulate", "{f}", "--trajectory", "{csv}"], ["plan", "{f}"], ["physics", "{f}"],
    ["cdpr", "tensions", "{f}", *POSE], ["cdpr", "wrench-set", "{f}", *POSE],
    ["cdpr", "workspace", "{f}"], ["cdpr", "twist-set", "{f}", *POSE],
    ["cdpr", "deploy", "{f}", *BOX], ["cdpr", "simulate", "{f}", *WAYPOINTS],
    ["app", "{f}", "--port", "0"],
], ids=lambda c: " ".join(c[:2]))
def test_every_command_refuses_a_bomb_in_one_line(tmp_path, capsys, command):
    path = tmp_path / "bomb.yaml"
    path.write_text("name: x\n" + bomb())
    csv = tmp_path / "t.csv"
    csv.write_text("time,x1,y1\n0,0,0\n")
    t0 = time.perf_counter()
    assert main([c.format(f=path, csv=csv) for c in command]) == 2
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


@pytest.mark.parametrize("module, extra", [
    ("mujoco", "physics"), ("dask", "sweep"), ("starlette", "app"), ("ompl", "plan-ompl")])
def test_a_missing_extra_is_named_in_one_line(monkeypatch, capsys, scenario_json, module,
                                              extra):
    """An optional dependency (the four of the issue) missing deep inside a command: one
    line naming the extra, not a ModuleNotFoundError traceback."""
    import importlib
    import sys

    from taut.cli import plan as plan_cli

    def needs_extra(*args, **kwargs):
        importlib.import_module(module + ".sub")
    monkeypatch.setitem(sys.modules, module, None)
    monkeypatch.setattr("taut.plan.planner.run_plan", needs_extra)
    assert plan_cli is not None
    assert main(["plan", "sc.json"]) == 2
    err = capsys.readouterr().err
    assert err == (f"taut: error: {module}: not installed; install taut[{extra}] "
                   f"(pip install 'taut[{extra}]')\n")


# --- figures and animations ---------------------------------------------------------------

@pytest.mark.parametrize("spell", ["same", "hardlink", "symlink"])
def test_a_figure_over_an_input_is_refused(tmp_path, monkeypatch, capsys, spell):
    """`--plot` goes through the same check as `--out`: a scenario that happens to carry
    a figure's extension (or a link to it) is not overwritten by the figure."""
    monkeypatch.chdir(tmp_path)
    Path("sc.png").write_text((ROOT / "examples" / "sheet" / "example1.yaml").read_text())
    before = Path("sc.png").read_bytes()
    out = "sc.png"
    if spell == "hardlink":
        os.link("sc.png", out := "fig.png")
    if spell == "symlink":
        os.symlink("sc.png", out := "fig.svg")
    assert main(["fk", "sc.png", "--plot", out]) == 2
    err = capsys.readouterr().err
    assert err.startswith("taut: error: --plot: ") and "is also an input" in err
    assert Path("sc.png").read_bytes() == before


def test_an_animation_over_an_input_is_refused(scenario_json, capsys):
    os.link("sc.json", "replay.gif")
    before = scenario_json.read_bytes()
    t0 = time.perf_counter()
    assert main(["plan", "sc.json", "--animate", "replay.gif"]) == 2
    assert time.perf_counter() - t0 < 5                # refused before planning
    assert "--animate: 'replay.gif' is also an input" in capsys.readouterr().err
    assert scenario_json.read_bytes() == before


def test_figures_and_animations_are_written_atomically(tmp_path):
    """A save that fails midway leaves the old file and no temporary; one that succeeds
    replaces the file with a complete PNG / GIF."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    from taut.viz._save import save_animation, save_figure

    png, gif = tmp_path / "f.png", tmp_path / "a.gif"
    png.write_bytes(b"old png")
    gif.write_bytes(b"old gif")
    fig, ax = plt.subplots()
    line, = ax.plot([0, 1], [0, 1])
    real = fig.savefig

    def half_then_fail(path, **kw):
        Path(path).write_bytes(b"\x89PNG half")
        raise OSError(28, "No space left on device")

    fig.savefig = half_then_fail
    with pytest.raises(OSError):
        save_figure(fig, png, dpi=50)
    assert png.read_bytes() == b"old png"
    fig.savefig = real

    def broken(k):
        if k == 2:
            raise RuntimeError("frame 2 cannot be drawn")
        line.set_ydata([0, k])
        return (line,)

    with pytest.raises(RuntimeError):
        save_animation(FuncAnimation(fig, broken, frames=4), gif, fps=5)
    assert gif.read_bytes() == b"old gif"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "f.png"]

    save_figure(fig, png, dpi=50)
    save_animation(FuncAnimation(fig, lambda k: broken(1), frames=3), gif, fps=5)
    plt.close(fig)
    assert png.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "f.png"]


def test_every_figure_is_saved_through_the_atomic_writer():
    """No module of taut.viz writes a figure or an animation itself."""
    import re

    viz = ROOT / "src" / "taut" / "viz"
    direct = [f"{p.name}:{n}" for p in sorted(viz.glob("*.py")) if p.name != "_save.py"
              for n, line in enumerate(p.read_text().splitlines(), 1)
              if re.search(r"\.savefig\(|\banim\w*\.save\(|PillowWriter", line)]
    assert direct == []


@pytest.mark.parametrize("option, name", [("--mcap", "rec.mcap"), ("--rerun", "rec.rrd"),
                                          ("--trajectories", "tr.json")])
def test_a_recording_over_its_scenario_is_refused(scenario_json, capsys, option, name):
    """Every output option goes through the same input check as --out: a recording or
    trajectory file that is the scenario (here a link to it with the output's extension)
    is refused before planning, the input intact."""
    before = scenario_json.read_bytes()
    os.symlink("sc.json", name)
    assert main(["plan", "sc.json", option, name]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"taut: error: {option}: ") and "is also an input" in err
    assert err.count("\n") == 1
    assert scenario_json.read_bytes() == before


def _pairs_file(path, pairs, json_form):
    """A sheet scenario whose formation holds ``pairs`` number pairs (wrongly many robots:
    the command reads the whole file, then refuses the formation)."""
    rows = ", ".join(f"[{k}.5, {k}.25]" for k in range(pairs))
    if json_form:
        text = ('{"hold_height": 1000, "sheet": [[0, 0], [1000, 0], [0, 1000]], '
                f'"formation": [{rows}]}}')
    else:
        text = f"hold_height: 1000\nsheet: [[0, 0], [1000, 0], [0, 1000]]\nformation: [{rows}]\n"
    path.write_text(text)
    return text


def test_yaml_past_its_length_limit_is_refused_in_one_line(tmp_path, capsys):
    """A YAML parser holds an object per value (a 32 MiB YAML file of numbers would take
    ~3 GB), so YAML is read up to MAX_YAML_CHARS characters, JSON up to MAX_FILE_BYTES."""
    from taut.io import MAX_FILE_BYTES, MAX_YAML_CHARS
    text = _pairs_file(tmp_path / "big.yaml", MAX_YAML_CHARS // 16, json_form=False)
    assert MAX_YAML_CHARS < len(text) < MAX_FILE_BYTES
    t0 = time.perf_counter()
    assert main(["fk", str(tmp_path / "big.yaml")]) == 2
    assert time.perf_counter() - t0 < 5
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "write larger data as JSON" in err, err


@pytest.mark.slow
@pytest.mark.parametrize("json_form", [False, True])
def test_the_largest_readable_file_keeps_a_command_under_1_gib(tmp_path, json_form):
    """The largest file a command reads (YAML just under MAX_YAML_CHARS, JSON just under
    MAX_FILE_BYTES, all numbers) keeps `taut fk`'s peak resident memory under 1 GiB: it is
    read whole, then refused in one line. Measured 0.39 GB (4 MB YAML), 0.72 GB (31 MiB
    JSON)."""
    import subprocess
    import sys
    from taut.io import MAX_FILE_BYTES, MAX_YAML_CHARS
    limit = MAX_FILE_BYTES if json_form else MAX_YAML_CHARS
    path = tmp_path / ("big.json" if json_form else "big.yaml")
    n = limit // 25
    n = int(n * 0.95 * limit / len(_pairs_file(path, n, json_form)))
    text = _pairs_file(path, n, json_form)
    assert 0.9 * limit < len(text) < limit
    probe = ("import resource, subprocess, sys; r = subprocess.run(sys.argv[1:], "
             "capture_output=True, text=True); print(r.returncode, "
             "resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss); "
             "print(r.stderr.strip())")
    taut = str(Path(sys.executable).with_name("taut"))
    out = subprocess.run([sys.executable, "-c", probe, taut, "fk", str(path)],
                         capture_output=True, text=True, timeout=600).stdout.splitlines()
    code, peak_kib = map(int, out[0].split())
    assert code == 2 and out[1].startswith("taut: error: formation: "), out
    assert peak_kib < 2**20, f"peak {peak_kib / 2**20:.2f} GiB"
