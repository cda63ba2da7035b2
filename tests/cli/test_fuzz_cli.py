"""Standing fuzz test of the command line: every command is driven with a generated set of
wrong inputs (bad output paths, empty/binary/garbage files, NaN/inf/1e308, wrong shapes,
unknown and duplicate keys, booleans, negative sizes). Each must exit 2 with exactly one
``taut: error: <field>: <problem>`` line on stderr, nothing on stdout, no traceback, and
quickly (every check runs before any solver).

Run in-process through :func:`taut.cli.main` (no subprocess) to stay fast. The number of
generated inputs per command is printed by ``test_report_counts`` (``pytest -s``).
"""

from __future__ import annotations

import collections
import itertools
import time
from pathlib import Path

import pytest
import yaml

from taut.cli import main

ROOT = Path(__file__).parents[2]
SHEET = ROOT / "examples" / "sheet" / "example1.yaml"
SQUARE = ROOT / "examples" / "sheet" / "trajectories" / "square4.yaml"
TRAJ = ROOT / "examples" / "sheet" / "trajectories" / "square4_jump.csv"
PLAN = ROOT / "examples" / "plan" / "paper_corridor.yaml"

#: Wall-clock bound of one rejected input, s (generous: the test machine is shared).
BOUND_S = 10.0

BAD_NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "abc", "", "true"]
BAD_COUNTS = ["-1", "0", "1.5", "x", "1000000000"]
#: Output names that must be refused before any work: (value, what is wrong).
BAD_OUTPUTS = ["", "noext", "fig.jpg", ".", "/proc/none/x.png", "{tmp}/file.txt/x.png",
               "{tmp}", "{tmp}/"]

COUNTS: collections.Counter[str] = collections.Counter()


def _bad_files(tmp: Path) -> list[Path]:
    """Files that are not scenarios/models at all."""
    out = []
    for name, data in [("empty.yaml", b""), ("binary.yaml", bytes(range(256)) * 4),
                       ("garbage.yaml", b"{[: ::: -"), ("list.yaml", b"- 1\n- 2\n"),
                       ("scalar.json", b"3"), ("broken.json", b'{"a": '),
                       ("latin1.yaml", "hold_height: \xe9".encode("latin-1")),
                       ("deep.json", b"[" * 5000 + b"]" * 5000)]:
        p = tmp / name
        p.write_bytes(data)
        out.append(p)
    out.append(tmp / "missing.yaml")
    out.append(tmp)                                 # a directory
    return out


def _sheet_mutations(tmp: Path) -> list[Path]:
    """Example 1 with one key replaced by a wrong value, or an extra/duplicate key."""
    base = yaml.safe_load(SHEET.read_text())
    bad_values = {
        "hold_height": [True, False, float("nan"), float("inf"), 1e308, -1.0, 0.0, "abc",
                        [], None],
        "mass": [True, float("nan"), -1.0, 0.0, 1e308, "heavy", [1.0]],
        "sheet": [[], [[1.0]], [[0, 0], [1, 0]], [[1e308, 0], [0, 1], [1, 1], [0, 2]],
                  [[0, 0], [1, 0], [0, 1], [1, 1]], "square", -1, [[True, 0], [1, 0], [0, 1],
                                                                   [1, 1]]],
        "formation": [[], [[0, 0]], [[float("nan"), 0]] * 4, [[1e308, 0]] * 4, "here",
                      [[0, 0], [5000, 0], [0, 5000], [5000, 5000]]],
    }
    out = []
    for key, values in bad_values.items():
        for k, v in enumerate(values):
            doc = dict(base)
            doc[key] = v
            p = tmp / f"sheet_{key}_{k}.yaml"
            p.write_text(yaml.safe_dump(doc))
            out.append(p)
    extra = tmp / "sheet_unknown.yaml"
    extra.write_text(SHEET.read_text() + "\ncolour: red\n")
    dup = tmp / "sheet_duplicate.yaml"
    dup.write_text(SHEET.read_text() + "\nhold_height: 900\n")
    return out + [extra, dup]


def _plan_mutations(tmp: Path) -> list[Path]:
    base = yaml.safe_load(PLAN.read_text())
    team_bad = {"regular": [{"n": 1000000000, "circumradius": 0.5}, {"n": -3, "circumradius": 1},
                            {"n": True, "circumradius": 1}, {"n": 3, "circumradius": "x"}],
                "hold_height": [True, float("nan"), -0.5, "high"],
                "speed": [0.0, -1.0, float("inf")], "colour": ["red"]}
    top_bad = {"start": [[float("nan"), 0], [0.8], "here", [100.0, 0.0]],
               "goal": [[1e308, 0.0]], "free_space": [[], [[0, 0], [1, 1]]],
               "obstacles": [[{"id": "1", "center": [2, 0], "radius": -1, "height": 0.1}],
                             "none"], "extra": [1]}
    out = []
    for key, values in team_bad.items():
        for k, v in enumerate(values):
            doc = yaml.safe_load(PLAN.read_text())
            doc["team"][key] = v
            p = tmp / f"plan_team_{key}_{k}.yaml"
            p.write_text(yaml.safe_dump(doc))
            out.append(p)
    for key, values in top_bad.items():
        for k, v in enumerate(values):
            doc = dict(base)
            doc[key] = v
            p = tmp / f"plan_{key}_{k}.yaml"
            p.write_text(yaml.safe_dump(doc))
            out.append(p)
    return out


def _bad_csvs(tmp: Path) -> list[Path]:
    rows = {"empty.csv": "", "header_only.csv": "t,x1,y1\n", "text.csv": "a,b,c\n1,2,x\n",
            "nan.csv": "0," + ",".join(["nan"] * 8) + "\n",
            "width.csv": "0,1,2,3\n1,1,2,3\n", "time.csv": "1," + ",".join(["0"] * 8) + "\n"
                                                           "0," + ",".join(["0"] * 8) + "\n",
            "huge.csv": "0," + ",".join(["1e308"] * 8) + "\n"}
    out = []
    for name, text in rows.items():
        p = tmp / name
        p.write_text(text)
        out.append(p)
    p = tmp / "binary.csv"
    p.write_bytes(b"\x00\xff\xfe" * 50)
    return out + [p, tmp / "nofile.csv"]


def _outputs(tmp: Path) -> list[str]:
    (tmp / "file.txt").write_text("x")
    return [o.format(tmp=tmp) for o in BAD_OUTPUTS]


def generate(tmp: Path) -> list[tuple[str, list[str]]]:
    """Every (command name, argv) pair of the fuzz set."""
    cases: list[tuple[str, list[str]]] = []
    files = [str(p) for p in _bad_files(tmp)]
    sheets = [str(p) for p in _sheet_mutations(tmp)]
    outs = _outputs(tmp)
    sheet = str(SHEET)
    # fk: bad files, mutated scenarios, bad options, bad outputs
    cases += [("fk", ["fk", f]) for f in files + sheets]
    cases += [("fk", ["fk", sheet, "--mass", v]) for v in BAD_NUMBERS + ["0", "-1"]]
    cases += [("fk", ["fk", sheet, "--method", m]) for m in ["", "magic", "FAST"]]
    cases += [("fk", ["fk", sheet, opt, o]) for opt in ("--plot", "--mcap", "--rerun")
              for o in outs]
    cases += [("fk", ["fk", sheet, "--nosuch"]), ("fk", ["fk"])]
    # ik
    cases += [("ik", ["ik", f, "--object", "0", "0", "300"]) for f in files + sheets[:12]]
    cases += [("ik", ["ik", sheet, "--object", v, "0", "300"]) for v in BAD_NUMBERS]
    cases += [("ik", ["ik", sheet, "--object", "0", "0"]),
              ("ik", ["ik", sheet, "--object", "0", "0", "300", "--mass", "1e308"]),
              ("ik", ["ik", sheet, "--object", "0", "0", "300", "--heading", "nan"]),
              ("ik", ["ik", sheet, "--object", "0", "0", "300", "--contact", "inf", "0"])]
    # simulate
    csvs = [str(p) for p in _bad_csvs(tmp)]
    cases += [("simulate", ["simulate", str(SQUARE), "--trajectory", c]) for c in csvs]
    cases += [("simulate", ["simulate", f, "--trajectory", str(TRAJ)]) for f in files]
    cases += [("simulate", ["simulate", str(SQUARE), "--trajectory", str(TRAJ), "--plot", o])
              for o in outs]
    cases += [("simulate", ["simulate", str(SQUARE), "--trajectory", str(TRAJ), "--mass", v])
              for v in BAD_NUMBERS]
    # plan
    cases += [("plan", ["plan", f]) for f in files + [str(p) for p in _plan_mutations(tmp)]]
    for opt in ("--plot", "--animate", "--out", "--mcap", "--rerun"):
        cases += [("plan", ["plan", str(PLAN), opt, o]) for o in outs]
    cases += [("plan", ["plan", str(PLAN), "--search", v])
              for v in ["", "ompl", "RRTConnect", "ompl-rrt", "prm", "1"]]
    for opt in ("--spacing", "--robustness", "--trials"):
        cases += [("plan", ["plan", str(PLAN), opt, v]) for v in BAD_NUMBERS]
    # cdpr
    models = ["nosuch"] + files
    pose = ["--pose", "0", "0", "1"]
    for cmd in ("tensions", "wrench-set", "twist-set"):
        cases += [(f"cdpr {cmd}", ["cdpr", cmd, m, *pose]) for m in models]
        for k, v in itertools.product(range(3), BAD_NUMBERS):
            p = ["0", "0", "1"]
            p[k] = v
            cases.append((f"cdpr {cmd}", ["cdpr", cmd, "fastkit", "--pose", *p]))
        cases += [(f"cdpr {cmd}", ["cdpr", cmd, "fastkit", *pose, "--rpy", v, "0", "0"])
                  for v in BAD_NUMBERS]
    cases += [("cdpr tensions", ["cdpr", "tensions", "fastkit", *pose, "--method", "x"])]
    cases += [("cdpr wrench-set", ["cdpr", "wrench-set", "fastkit", *pose, "--plot", o])
              for o in outs]
    cases += [("cdpr wrench-set", ["cdpr", "wrench-set", "fastkit", *pose, "--external-wrench",
                                   v, "0", "0", "0", "0", "0"]) for v in BAD_NUMBERS]
    cases += [("cdpr twist-set", ["cdpr", "twist-set", "fastkit", *pose, opt, v])
              for opt in ("--base-speed", "--yaw-rate", "--cable-speed")
              for v in BAD_NUMBERS + ["0", "-1"]]
    cases += [("cdpr twist-set", ["cdpr", "twist-set", "fastkit", *pose, "--mode", "fly"]),
              ("cdpr twist-set", ["cdpr", "twist-set", "fastkit", *pose, "--moving", "ghost"])]
    cases += [("cdpr twist-set", ["cdpr", "twist-set", "fastkit", *pose, "--plot", o])
              for o in outs]
    ws = ["-1", "1", "-0.05", "0.05", "0.2", "1"]
    cases += [("cdpr workspace", ["cdpr", "workspace", m]) for m in models]
    cases += [("cdpr workspace", ["cdpr", "workspace", "fastkit", "--grid", v, "1", "3"])
              for v in BAD_COUNTS]
    cases += [("cdpr workspace", ["cdpr", "workspace", "fastkit", "--box", *b]) for b in
              (["1", "-1", "0", "0", "0.2", "1"], ["-1", "1", "0", "0", "1", "0.2"],
               ["nan", *ws[1:]], ["-1e308", *ws[1:]], ["-1", "1"])]
    cases += [("cdpr workspace", ["cdpr", "workspace", "fastkit", "--sweep", v])
              for v in BAD_NUMBERS + ["-0.1", "10"]]
    cases += [("cdpr workspace", ["cdpr", "workspace", "fastkit", "--plot", o]) for o in outs]
    cases += [("cdpr deploy", ["cdpr", "deploy", m, "--workspace", *ws]) for m in models]
    for k, v in itertools.product(range(6), ["nan", "1e308", "-1e308", "x"]):
        b = list(ws)
        b[k] = v
        cases.append(("cdpr deploy", ["cdpr", "deploy", "fastkit", "--workspace", *b]))
    cases += [("cdpr deploy", ["cdpr", "deploy", "fastkit", "--workspace", *b]) for b in
              (["1", "-1", "0", "0.1", "0.2", "1"], ["-1", "1", "0", "0.1", "-1", "-0.2"],
               ["-1", "1", "0", "0", "0.2", "1"])]
    cases += [("cdpr deploy", ["cdpr", "deploy", "fastkit", "--workspace", *ws, opt, v])
              for opt, v in (("--seed", "-1"), ("--maxiter", "-1"), ("--maxiter", "10000000"),
                             ("--seed", "x"))]
    cases += [("cdpr deploy", ["cdpr", "deploy", "fastkit", "--workspace", *ws, "--twist",
                               v, "0", "0", "0", "0", "0"]) for v in BAD_NUMBERS]
    cases += [("cdpr deploy", ["cdpr", "deploy", "fastkit", "--workspace", *ws, "--plot", o])
              for o in outs]
    cases += _sweep_cases(tmp, files, outs)
    # cdpr simulate: every check comes before the plant is built
    wp = ["--waypoints", "-0.5,0,1.0; 0.5,0,1.0"]
    cases += [("cdpr simulate", ["cdpr", "simulate", m, *wp]) for m in models]
    cases += [("cdpr simulate", ["cdpr", "simulate", "fastkit", "--waypoints", w]) for w in
              ("", "0,0,1", "a,b,c; 1,2,3", "0,0,nan; 1,0,1", "0,0,1;1e308,0,1", "0,0; 1,1")]
    cases += [("cdpr simulate", ["cdpr", "simulate", "fastkit", *wp, opt, v])
              for opt in ("--speed", "--exit-error", "--control-rate", "--dwell")
              for v in BAD_NUMBERS + ["-1"]]
    cases += [("cdpr simulate", ["cdpr", "simulate", "fastkit", *wp, "--controller", c])
              for c in ("", "pid", "VELOCITY")]
    cases += [("cdpr simulate", ["cdpr", "simulate", "fastkit", *wp, opt, o])
              for opt in ("--plot", "--animate", "--out", "--mcap") for o in outs]
    cases += [("cdpr simulate", ["cdpr", "simulate", "fastkit", "--reference", c])
              for c in [str(p) for p in _bad_csvs(tmp)]]
    # physics (MuJoCo): every check comes before the model is built
    cases += [("physics", ["physics", f]) for f in files + sheets]
    cases += [("physics", ["physics", sheet, "--plot", o]) for o in outs]
    cases += [("physics", ["physics", sheet, "--video", o]) for o in outs + [str(tmp / "a.png")]]
    cases += [("physics", ["physics", sheet, "--mesh", v]) for v in BAD_COUNTS + ["2", "61"]]
    # app: every check (file, port, host) comes before the server starts
    cases += [("app", ["app", f]) for f in files]
    cases += [("app", ["app", "--port", v]) for v in ("-1", "65536", "x", "1e308", "nan", "")]
    cases += [("app", ["app", "--host", "999.1.1.1"])]
    cases += [("taut", [w]) for w in ("nosuch", "--nosuch", "cdpr nosuch")]
    return cases


def _sweep_cases(tmp: Path, files: list[str], outs: list[str]) -> list[tuple[str, list[str]]]:
    """`taut sweep`: bad files, mutated sweep files, bad options, bad figure paths."""
    good = {"task": "fk_stability_map", "base": str(SHEET),
            "parameters": {"scale": {"range": [0.8, 1.0], "num": 3}}}
    mutations = [{"task": "nope"}, {"task": True}, {"base": str(tmp / "none.yaml")},
                 {"base": None}, {"parameters": {}}, {"parameters": {"scal": 1}},
                 {"parameters": {"scale": {"range": [1, 0], "num": 3}}},
                 {"parameters": {"scale": {"range": [0, 1], "num": 0}}},
                 {"parameters": {"scale": {"range": [0, 1], "step": -1}}},
                 {"parameters": {"scale": []}}, {"parameters": {"scale": True}},
                 {"parameters": {"scale": float("nan")}}, {"parameters": {"scale": "big"}},
                 {"mode": "random"}, {"mode": "random", "samples": -5},
                 {"mode": "random", "samples": 3, "parameters": {"scale": {"uniform": [1, 1]}}},
                 {"outputs": ["n_stabel"]}, {"outputs": "n_stable"}, {"seed": -1},
                 {"seed": 1.5}, {"chunk_size": -1}, {"colour": "red"}, {"options": 3}]
    specs = []
    for k, change in enumerate(mutations):
        p = tmp / f"sweep_{k}.yaml"
        p.write_text(yaml.safe_dump({**good, **change}))
        specs.append(str(p))
    dup = tmp / "sweep_dup.yaml"
    dup.write_text(yaml.safe_dump(good) + "task: plan_suite\n")
    specs.append(str(dup))
    ok = tmp / "sweep_ok.yaml"
    ok.write_text(yaml.safe_dump(good))
    (tmp / "sweep_file").write_text("x")
    out = str(tmp / "sweep_out")
    cases = [("sweep", ["sweep", f, "--out", out]) for f in files + specs]
    cases += [("sweep", ["sweep", str(ok), "--out", out, opt, v])
              for opt, v in (("--workers", "-1"), ("--workers", "x"), ("--limit", "0"),
                             ("--limit", "-3"), ("--limit", "1.5"))]
    cases += [("sweep", ["sweep", str(ok), "--out", str(tmp / "sweep_file")]),
              ("sweep", ["sweep", str(ok)]), ("sweep", ["sweep", str(ok), "--out"])]
    cases += [("sweep", ["sweep", "plot", d, "--x", "scale", "--value", "n_stable"])
              for d in (str(tmp), str(tmp / "none"))]
    return cases


def _cases() -> list[tuple[str, list[str]]]:
    import atexit
    import shutil
    import tempfile
    tmp = Path(tempfile.mkdtemp(prefix="taut_fuzz_"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    return generate(tmp)


CASES = _cases()


@pytest.mark.parametrize("command,argv", CASES,
                         ids=[f"{c}-{k}" for k, (c, _) in enumerate(CASES)])
def test_wrong_input_is_one_line_exit_2(capsys, command, argv):
    start = time.monotonic()
    code = main(argv)
    elapsed = time.monotonic() - start
    out, err = capsys.readouterr()
    COUNTS[command] += 1
    lines = err.splitlines()
    assert "Traceback" not in err and "Warning" not in err, err
    assert code == 2, (argv, code, out, err)
    assert len(lines) == 1 and lines[0].startswith("taut: error: "), err
    assert lines[0].count(":") >= 2, err                # taut: error: <field>: <problem>
    assert out == "", out
    assert elapsed < BOUND_S, f"{argv} took {elapsed:.1f} s"


def test_every_command_is_fuzzed():
    commands = collections.Counter(c for c, _ in CASES)
    want = {"fk", "ik", "simulate", "plan", "cdpr tensions", "cdpr wrench-set",
            "cdpr workspace", "cdpr twist-set", "cdpr deploy", "sweep", "physics",
            "cdpr simulate"}
    assert want <= set(commands)
    assert min(commands[c] for c in want) >= 20


def test_report_counts(capsys):
    commands = collections.Counter(c for c, _ in CASES)
    with capsys.disabled():
        print("\nfuzz inputs per command: " + ", ".join(f"{c} {n}" for c, n in
                                                       sorted(commands.items())))
    assert sum(commands.values()) == len(CASES)
