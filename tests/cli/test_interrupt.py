"""Ctrl-C is an answer (issue 24): SIGINT sent to a running `taut` command ends it with
exit code 130 and the one line ``taut: interrupted`` on stderr, whatever was running
(numba kernels included), and a sweep keeps the chunks it had written."""

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
TAUT = Path(sys.executable).with_name("taut")


def interrupt(args, ready, cwd=ROOT, limit=60.0):
    """Start ``taut args``, wait until stderr shows ``ready`` (a progress line: the
    command is computing), send SIGINT; returns (exit code, stderr lines)."""
    proc = subprocess.Popen([str(TAUT), *args], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    lines = []
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        line = proc.stderr.readline()
        if not line:
            break
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
                            "taut: plan: working")
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


@pytest.mark.parametrize("args", [
    ["cdpr", "workspace", "fastkit", "--grid", "301", "1", "301"],
    ["cdpr", "simulate", "fastkit", "--stabilisers", "--waypoints",    # ~10 s idle
     "; ".join(["-0.5,0,1.0", "0.5,0,1.0"] * 100)],
], ids=lambda a: " ".join(a[:2]))
def test_cable_robot_commands_interrupted(args):
    """A workspace grid (a loop of solver calls) and a control simulation (a compiled
    kernel), stopped once they report progress: one line, exit 130."""
    code, lines = interrupt(args, ": working")
    assert code == 130
    assert lines[-1] == "taut: interrupted"
    assert not any("Traceback" in x or "SystemError" in x for x in lines), lines
