"""Ctrl-C is an answer (issue 24): SIGINT sent to a running `taut` command ends it with
exit code 130 and the one line ``taut: interrupted`` on stderr, whatever was running
(numba kernels included), and a sweep keeps the chunks it had written."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).parents[2]
TAUT = Path(sys.executable).with_name("taut")


def interrupt(args, ready, cwd=ROOT, limit=60.0, after=0.2):
    """Start ``taut args``, wait until stderr shows ``ready`` (a progress line: the
    command is computing; the first comes ``after`` seconds into the work,
    ``TAUT_PROGRESS_AFTER_S``, None: the default), send SIGINT; returns (exit code,
    stderr lines)."""
    env = dict(os.environ)
    if after is not None:
        env["TAUT_PROGRESS_AFTER_S"] = str(after)
    proc = subprocess.Popen([str(TAUT), *args], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, env=env)
    lines = []
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        line = proc.stderr.readline()
        if not line:
            proc.wait(30)
            pytest.fail(f"finished (exit {proc.returncode}) before showing progress: {lines}")
        lines.append(line.rstrip("\n"))
        if ready in line:
            break
    else:
        proc.kill()
        pytest.fail("the command never showed progress")
    assert proc.poll() is None, f"finished before the interrupt: {lines}"
    proc.send_signal(signal.SIGINT)
    rest = proc.communicate(timeout=30)[1]
    return proc.returncode, lines + rest.splitlines()


def test_plan_interrupted_in_compiled_code():
    code, lines = interrupt(["plan", "examples/plan/turned_corridor_5.yaml"],
                            "taut: plan: working", after=None)   # 2 s in: the lattice search
    assert code == 130
    assert lines[-1] == "taut: interrupted"
    assert not any("Traceback" in x or "SystemError" in x for x in lines), lines


def test_serial_sweep_interrupted_keeps_its_chunks(tmp_path):
    out = tmp_path / "out"
    code, lines = interrupt(["sweep", "run", "examples/sweeps/octagon_stability.yaml",
                             "--workers", "0", "--out", str(out)], "points/s")
    assert code == 130
    assert lines[-1] == "taut: interrupted"
    assert sum("interrupted" in x for x in lines) == 1
    assert not any("Traceback" in x for x in lines), lines
    assert list((out / "chunks").glob("*.parquet")), "the finished chunks were lost"


# The simulation case is in the slow target (CI runs it), to keep `make test` under its
# budget; the workspace case keeps the command's interrupt in the fast suite, and
# test_plan_interrupted_in_compiled_code an interrupt inside a compiled kernel.
@pytest.mark.parametrize("args", [
    ["cdpr", "workspace", "fastkit", "--grid", "301", "1", "301"],
    pytest.param(["cdpr", "simulate", "fastkit", "--stabilisers",   # 56 s simulated: ~40 s
                  "--controller", "computed_torque", "--waypoints",
                  "; ".join(["-0.5,0,1.0", "0.5,0,1.0"] * 13)], marks=pytest.mark.slow),
], ids=lambda a: " ".join(a[:2]))
def test_cable_robot_commands_interrupted(args):
    """A workspace grid (a loop of solver calls) and a control simulation (a compiled
    kernel), stopped once they report progress: one line, exit 130."""
    code, lines = interrupt(args, ": working")
    assert code == 130
    assert lines[-1] == "taut: interrupted"
    assert not any("Traceback" in x or "SystemError" in x for x in lines), lines


# --- every other command (issue 24, item 4: "every command exits 130") -----------------

def assert_interrupted(code, lines):
    assert code == 130, lines
    assert lines[-1] == "taut: interrupted"
    assert sum("interrupted" in x for x in lines) == 1, lines
    assert not any("Traceback" in x or "SystemError" in x for x in lines), lines


def big_team(n=1000):
    """A sheet scenario of ``n`` robots (the most the library takes): a regular n-gon held
    near its rim, as the app's heavy FK request."""
    from taut.sheet import Sheet
    sheet = Sheet.regular(n, 1000.0)
    formation = 0.8 * sheet.vertices + np.random.default_rng(0).uniform(-0.5, 0.5, (n, 2))
    return {"units": "mm", "hold_height": 1000.0, "mass": 1.0,
            "sheet": np.round(sheet.vertices, 6).tolist(),
            "formation": np.round(formation, 6).tolist()}


def swaying(tmp_path, team, steps):
    """``team`` (a scenario mapping) written to ``team.json``, and a CSV trajectory of
    ``steps`` rows swaying its formation by 3 sheet units."""
    (tmp_path / "team.json").write_text(json.dumps(team))
    f0 = np.asarray(team["formation"], dtype=float)
    sway = 3 * np.sin(2 * np.pi * np.arange(steps) / 40)
    rows = [",".join([f"{0.01 * k:.2f}", *(f"{v:.6f}" for v in (f0 + s * np.array([1, 0.5]))
                                           .ravel())]) for k, s in enumerate(sway)]
    (tmp_path / "walk.csv").write_text("\n".join(rows) + "\n")
    return tmp_path / "team.json", tmp_path / "walk.csv"


# The slow target (CI runs it; ~2 s of CPU, a process started and run to its progress line):
# test_plan_interrupted_in_compiled_code keeps an interrupt inside a compiled kernel, and
# test_simulate_interrupted a sheet command's, in the fast suite.
@pytest.mark.slow
def test_fk_exhaustive_interrupted(tmp_path):
    """The paper's Algorithm 1 over every taut set of a 20-robot team (2^20 sets, 11 s of
    CPU): `taut fk` of the largest team answers before its first progress line, this
    method does not."""
    (tmp_path / "team.json").write_text(json.dumps(big_team(20)))
    assert_interrupted(*interrupt(["fk", str(tmp_path / "team.json"), "--method",
                                   "exhaustive"], "taut: fk (exhaustive): working"))


def ring_of_cables(m):
    """A fixed-frame cable robot of ``m`` cables (a model mapping, SI units): exits
    alternately on a top (z = 3 m) and a bottom (z = 0 m) ring of radius 2 m, each cable to
    its own attachment point on a 0.15 m ring of the platform."""
    a = 2 * np.pi * np.arange(m) / m
    exits = {f"A{i + 1}": [round(2 * np.cos(x), 6), round(2 * np.sin(x), 6), 3.0 - 3.0 * (i % 2)]
             for i, x in enumerate(a)}
    points = {f"B{i + 1}": [round(0.15 * np.cos(x + 0.3), 6), round(0.15 * np.sin(x + 0.3), 6),
                            0.1 - 0.2 * (i % 2)] for i, x in enumerate(a)}
    return {"name": f"ring of {m} cables",
            "bases": [{"name": "frame", "mobile": False, "exit_points": exits}],
            "platform": {"mass": 2.0, "inertia": [0.02, 0.02, 0.03],
                         "attachment_points": points},
            "cables": [{"name": f"C{i + 1}", "exit": f"frame.A{i + 1}", "attachment": f"B{i + 1}",
                        "t_min": 10.0, "t_max": 1500.0} for i in range(m)]}


def ring_of_bases(k, cables=None):
    """FASTKIT's cable robot with ``k`` copies of its active mobile base on a 3 m circle
    around the platform (a model mapping); ``cables[i]`` of the 4 exits of base ``i`` are
    used (default all 4)."""
    import yaml

    from taut.io.cdpr_model import preset_path
    fastkit = yaml.safe_load(preset_path("fastkit").read_text())
    base, points = fastkit["bases"][0], list(fastkit["platform"]["attachment_points"])
    bases, cables_ = [], []
    for i, phi in enumerate(2 * np.pi * np.arange(k) / k):
        bases.append(dict(base, name=f"base{i + 1}", pose=[round(-3 * np.cos(phi), 6),
                                                            round(-3 * np.sin(phi), 6),
                                                            round(phi, 6)]))
        used = list(base["exit_points"])[:4 if cables is None else cables[i]]
        cables_ += [{"name": f"C{j + 1}{i + 1}", "exit": f"base{i + 1}.{p}",
                     "attachment": points[(4 * i + j) % len(points)], "t_min": 5.0,
                     "t_max": 45.0} for j, p in enumerate(used)]
    return {"name": f"{k} mobile bases", "bases": bases, "platform": fastkit["platform"],
            "payload": fastkit["payload"], "cables": cables_}


@pytest.mark.parametrize("model, args", [
    # the largest inputs the set budget (taut._validate.MAX_SET_NUMBERS) accepts run for
    # seconds: a 6-DoF fixed ring of 12 cables (16.6 million numbers: ~9 s of CPU, 0.43 GB)
    # and 10 cables on 4 moving bases (28 million: ~5 s of CPU beyond start-up, 0.5 GB)
    # Both in the slow target (CI runs them; ~3 s of CPU each): the fast suite keeps a cable
    # robot command interrupted in its solver loop through
    # test_cable_robot_commands_interrupted[cdpr workspace] and
    # test_cable_robot_planners_interrupted[cdpr deploy].
    pytest.param(ring_of_cables(12), ["wrench-set"], id="wrench-set", marks=pytest.mark.slow),
    pytest.param(ring_of_bases(4, [3, 3, 2, 2]),
                 ["twist-set", *(f"--moving=base{i}" for i in range(1, 5))], id="twist-set",
                 marks=pytest.mark.slow),
])
def test_cable_robot_pose_commands_interrupted(tmp_path, model, args):
    """The one-pose analyses, on models whose size makes them take seconds."""
    (tmp_path / "model.json").write_text(json.dumps(model))
    assert_interrupted(*interrupt(["cdpr", args[0], str(tmp_path / "model.json"), "--pose",
                                   "0", "0", "1.5", *args[1:]], f"taut: cdpr {args[0]}: working"))


@pytest.mark.parametrize("model, args, field", [
    # `tensions` takes milliseconds for any accepted model (at most MAX_CABLES cables), so
    # it has no long input to interrupt: the 6,000-cable ring that used to take 5 s of CPU
    # and 1.3 GB is refused at once, as are sets past their budget (those two cases in the
    # slow target; tests/cdpr/sets/ test the set budget's refusal in-process)
    (ring_of_cables(6000), ["tensions"], "cables"),
    pytest.param(ring_of_cables(16), ["wrench-set"], "cables", marks=pytest.mark.slow),
    pytest.param(ring_of_bases(6), ["twist-set", "--moving", "base1", "--moving", "base2"],
                 "cables", marks=pytest.mark.slow),
])
def test_cable_robot_inputs_too_large_fail_fast(tmp_path, model, args, field):
    """One line, exit 2, before any progress line (so long before 2 s of work)."""
    (tmp_path / "model.json").write_text(json.dumps(model))
    proc = subprocess.run([str(TAUT), "cdpr", args[0], str(tmp_path / "model.json"), "--pose",
                           "0", "0", "1.5", *args[1:]], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(f"taut: error: {field}: ")


# IK of the largest team it takes (MAX_IK_ROBOTS, 200): Ctrl-C at its first progress line
# is answered in 0.2 s; later, mid-search, it waits for the current SLSQP step (4-6 s
# measured, load 3-5). Slow target (the team's IK runs ~50 s uninterrupted).
@pytest.mark.slow
def test_ik_of_the_largest_team_interrupted(tmp_path):
    from taut._validate import MAX_IK_ROBOTS
    (tmp_path / "team.json").write_text(json.dumps(big_team(MAX_IK_ROBOTS)))
    assert_interrupted(*interrupt(["ik", str(tmp_path / "team.json"), "--object", "0", "0",
                                   "500"], "taut: ik: working"))


def test_ik_of_a_team_past_its_limit_is_one_line(tmp_path):
    """1,000 robots (FK's limit): IK refuses at once (it used to run for minutes and grow
    past 14 GB), one line naming the field, exit 2."""
    (tmp_path / "team.json").write_text(json.dumps(big_team()))
    proc = subprocess.run([str(TAUT), "ik", str(tmp_path / "team.json"), "--object", "0", "0",
                           "500"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        "taut: error: sheet: 1000 robots; inverse kinematics takes at most 200 (its search "
        "grows as N^3 a step)"]


def test_simulate_interrupted(tmp_path):
    """1000 robots along 200 steps: ~50 ms a step (~5 s idle, 10 s loaded)."""
    team, walk = swaying(tmp_path, big_team(), 200)
    assert_interrupted(*interrupt(["simulate", str(team), "--trajectory", str(walk)],
                                  "taut: simulate: working"))


@pytest.mark.slow                   # ~9 s loaded: MuJoCo builds the sheet before a state settles
def test_physics_interrupted_in_mujoco(tmp_path):
    pytest.importorskip("mujoco", reason="needs the physics extra")
    from taut.app.catalog import regular_team
    team, _ = swaying(tmp_path, regular_team(12), 1)        # 15 states, seconds each
    assert_interrupted(*interrupt(["physics", str(team)], "taut: physics (settling each "
                                  "state): working"))


@pytest.mark.parametrize("args, ready", [
    (["cdpr", "deploy", "fastkit", "--workspace", "-0.5", "0.5", "-0.1", "0.1", "0.5", "1.0"],
     "taut: cdpr deploy: working"),                                   # ~2 min idle
    pytest.param(["cdpr", "mission", "examples/cdpr/warehouse.yaml"],  # ~25 s idle
                 "taut: cdpr mission (8 tasks): working",
                 marks=pytest.mark.slow),               # the slow target; deploy stays fast
], ids=lambda a: " ".join(a[:2]) if isinstance(a, list) else None)
def test_cable_robot_planners_interrupted(args, ready):
    assert_interrupted(*interrupt(args, ready))


def test_sweep_plot_of_a_large_sweep_interrupted(tmp_path):
    """A results folder of 10^6 points (a 1000 x 1000 map), drawn for seconds."""
    pa = pytest.importorskip("pyarrow", reason="needs the sweep extra")
    import pyarrow.parquet as pq
    x, y = np.meshgrid(np.linspace(0, 1, 1000), np.linspace(0, 2, 1000), indexing="ij")
    table = pa.table({"point": np.arange(x.size), "scale": x.ravel(), "angle": y.ravel(),
                      "share": np.random.default_rng(0).random(x.size)})
    pq.write_table(table, tmp_path / "results.parquet", row_group_size=100_000)
    code, lines = interrupt(["sweep", "plot", str(tmp_path), "--x", "scale", "--y", "angle",
                             "--value", "share"], "taut: sweep plot: working")
    assert_interrupted(code, lines)
    assert not (tmp_path / "share.png").exists()           # no figure, not half of one
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]


def descendants(pid):
    """Process ids of every descendant of ``pid`` (read from /proc)."""
    children: dict[int, list[int]] = {}
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                ppid = int((p / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(p.name))
    out, todo = [], [pid]
    while todo:
        found = children.get(todo.pop(), [])
        out += found
        todo += found
    return out


def running(pid):
    """Whether ``pid`` exists and is not a zombie."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.slow                       # ~15 s: a Dask cluster starts, then 5 s to a report
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_parallel_sweep_interrupted_ends_its_workers_and_keeps_its_chunks(tmp_path):
    """`--workers 2`: Ctrl-C ends the client and every process of its local Dask cluster
    (no orphan left computing), and the chunks already written are kept whole (each
    matches its checksum)."""
    import hashlib

    pytest.importorskip("distributed", reason="needs the sweep extra")
    out = tmp_path / "out"
    proc = subprocess.Popen([str(TAUT), "sweep", "run", "examples/sweeps/octagon_stability.yaml",
                             "--workers", "2", "--out", str(out)], cwd=ROOT,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines = []
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not any("points/s" in x for x in lines):
        line = proc.stderr.readline()
        if not line:
            break
        lines.append(line.rstrip("\n"))
    assert proc.poll() is None, lines
    family = descendants(proc.pid)
    assert len(family) >= 2, family                     # the two workers, at least
    proc.send_signal(signal.SIGINT)
    lines += proc.communicate(timeout=60)[1].splitlines()
    assert_interrupted(proc.returncode, lines)
    deadline = time.monotonic() + 15                    # the resource tracker takes ~1 s
    while any(running(p) for p in family) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not [p for p in family if running(p)], "orphan processes of the sweep"
    chunks = sorted((out / "chunks").glob("*.parquet"))
    assert chunks, "the finished chunks were lost"
    for chunk in chunks:
        digest = Path(f"{chunk}.sha256").read_text().split()[0]
        assert hashlib.sha256(chunk.read_bytes()).hexdigest() == digest, chunk.name


def test_an_interrupt_inside_llvmlite_is_raised_again_outside(monkeypatch):
    """Python drops an exception raised in a ctypes callback (llvmlite's object-cache
    notification, while numba compiles) and prints 'Exception ignored' with a traceback
    (seen in fresh-clone CI: Ctrl-C while `cdpr mission` compiled a kernel): there the
    handler returns and its timer raises the interrupt 50 ms later, outside; anywhere else
    it raises at once. Once raised, the timer raises it again only while the command
    computes (a swallowed interrupt), never outside ``working``."""
    from taut import cli
    from taut.cli import _progress
    armed = []
    monkeypatch.setattr(signal, "setitimer", lambda which, *times: armed.append(times))
    ns: dict = {}
    exec(compile("def notify(handler, signum):\n    import sys\n"
                 "    handler(signum, sys._getframe())\n",
                 "/site-packages/llvmlite/binding/executionengine.py", "exec"), ns)
    try:
        cli._interrupt.clear()
        cli._raised.clear()
        try:
            ns["notify"](cli._on_sigint, signal.SIGINT)   # returns: nothing raised in there
            ns["notify"](cli._on_sigint, signal.SIGALRM)  # the timer, still in there
        except KeyboardInterrupt:
            pytest.fail("KeyboardInterrupt raised inside the ctypes callback")
        assert armed == [(0.05, cli.REPEAT_INTERRUPT_S)] and cli._interrupt.is_set()
        with pytest.raises(KeyboardInterrupt):          # the timer, outside: raised
            cli._on_sigint(signal.SIGALRM, sys._getframe())
        cli._on_sigint(signal.SIGALRM, sys._getframe())  # raised once; not computing
        monkeypatch.setattr(_progress, "_open", [1])     # inside `working`: again
        with pytest.raises(KeyboardInterrupt):
            cli._on_sigint(signal.SIGALRM, sys._getframe())
        try:
            raise ValueError("cleanup on the way out")
        except ValueError:                               # an exception being handled
            cli._on_sigint(signal.SIGALRM, sys._getframe())
        cli._interrupt.clear()
        cli._raised.clear()
        with pytest.raises(KeyboardInterrupt):           # a plain frame: at once
            cli._on_sigint(signal.SIGINT, sys._getframe())
        assert len(armed) == 2
    finally:
        cli._interrupt.clear()
        cli._raised.clear()


@pytest.mark.parametrize("route", ["typer-exit-130", "outside-typer", "swallowed"])
def test_an_interrupt_is_reported_in_one_line_whatever_catches_it(monkeypatch, capsys, route):
    """typer turns a KeyboardInterrupt inside a command into ``Exit(130)``; one raised
    outside typer (a deferred one, 50 ms after a compile callback) reaches ``_run``'s
    handler; one a library swallowed is seen only by ``main``'s check. Each ends the
    command with 130 and exactly one ``taut: interrupted`` (`cdpr mission` printed two when
    the handler and ``main`` both reported it), and no timer outlives ``main``."""
    import typer

    from taut import cli
    timers: list[float] = []
    real_setitimer = signal.setitimer
    monkeypatch.setattr(signal, "setitimer",
                        lambda which, *times: timers.append(times[0]) or real_setitimer(
                            which, *times))

    def command(argv):
        cli._interrupt.set()                     # what _on_sigint does first
        if route == "typer-exit-130":
            raise typer.Exit(130)
        if route == "outside-typer":
            raise KeyboardInterrupt
        return 0                                 # swallowed: the command returned

    def run(argv):
        try:
            return command(argv)
        except KeyboardInterrupt:
            return cli._stopped()
        except typer.Exit as exc:
            return int(exc.exit_code)

    monkeypatch.setattr(cli, "_run", run)
    assert cli.main(["fk", "x.yaml"]) == cli.EXIT_INTERRUPTED
    assert capsys.readouterr().err.splitlines() == ["taut: interrupted"]
    assert timers[-1:] == [0]                    # any deferred interrupt cancelled


def test_an_interrupt_a_library_swallows_is_raised_again(tmp_path, monkeypatch):
    """A library that catches the KeyboardInterrupt (pyarrow's lazy import of pandas does)
    does not make the command run on: the interrupt is raised again within
    ``REPEAT_INTERRUPT_S`` while the command computes, and the figure is not written."""
    pa = pytest.importorskip("pyarrow", reason="needs the sweep extra")
    import pyarrow.parquet as pq
    import taut.cli.sweep as sweep_cli
    from taut.cli import REPEAT_INTERRUPT_S, main

    pq.write_table(pa.table({"point": np.arange(3), "scale": [0.5, 0.6, 0.7],
                             "share": [0.1, 0.2, 0.3]}), tmp_path / "results.parquet")
    seen = {}

    def swallowing_plot(folder, x, y, value, target, meta):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except BaseException as exc:               # what a careless library does
            seen["swallowed"] = type(exc).__name__
        t0 = time.monotonic()
        try:
            while time.monotonic() - t0 < 10:      # computing on, for up to 10 s
                sum(range(1000))
        finally:
            seen["computed_s"] = time.monotonic() - t0
        target.write_text("a figure")

    monkeypatch.setattr(sweep_cli, "_plot", swallowing_plot)
    code = main(["sweep", "plot", str(tmp_path), "--x", "scale", "--value", "share"])
    assert code == 130
    assert seen["swallowed"] == "KeyboardInterrupt"
    assert seen["computed_s"] < REPEAT_INTERRUPT_S + 0.5
    assert not (tmp_path / "share.png").exists()
