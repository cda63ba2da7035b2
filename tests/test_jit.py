"""The compiled-kernel set-up (src/taut/_jit.py, docs/compiled_kernels.md): which process
compiles, where the cache and stamp live, the numpy fallback and the per-call choice."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from taut import _jit
from taut.errors import InvalidInputError

SRC = Path(_jit.__file__).parent
EXAMPLE1 = Path(__file__).parent.parent / "examples" / "sheet" / "example1.yaml"


def _run(code: str, cache: Path | None, mode: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter with the numba cache ``cache`` (None: the
    suite's) and ``TAUT_NUMBA=mode``."""
    env = dict(os.environ, TAUT_NUMBA=mode)
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=600)


def _python(code: str, cache: Path | None, mode: str) -> str:
    """stdout of :func:`_run`, which must succeed."""
    out = _run(code, cache, mode)
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_every_kernel_file_keys_the_stamp():
    """A file that defines ``@jit`` kernels, or one whose names a kernel file imports
    (constants numba freezes into the machine code), missing from KERNEL_SOURCES would
    leave a stale stamp after an edit: processes would compile in the user's path."""
    kernels = {p for p in SRC.rglob("*.py")
               if re.search(r"^from \.+_jit import .*\bjit\b", p.read_text(), re.M)}
    needed = {"_jit.py"}
    for path in kernels:
        needed.add(path.relative_to(SRC).as_posix())
        for dots, module in re.findall(r"^from (\.+)(\w+) import", path.read_text(), re.M):
            base = path.parent
            for _ in range(len(dots) - 1):
                base = base.parent
            needed.add((base / f"{module}.py").relative_to(SRC).as_posix())
    assert len(kernels) >= 7
    assert needed == set(_jit.KERNEL_SOURCES)


def test_stamp_changes_with_a_kernel_source(tmp_path, monkeypatch):
    for rel in _jit.KERNEL_SOURCES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(SRC / rel, tmp_path / rel)
    monkeypatch.setattr(_jit, "_PACKAGE", str(tmp_path))
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    _jit.cache_dir.cache_clear()
    try:
        first = _jit.stamp_path.__wrapped__()
        assert first == _jit.stamp_path.__wrapped__()           # deterministic
        kernel = tmp_path / "plan" / "_kernels" / "clearance.py"
        kernel.write_text(kernel.read_text() + "\n# edited\n")
        second = _jit.stamp_path.__wrapped__()
    finally:
        _jit.cache_dir.cache_clear()
    assert first != second
    assert Path(first).parent == tmp_path / "cache"


def test_cache_dir_for_a_read_only_install(monkeypatch, tmp_path):
    """Package not writable: the user's cache; neither: a per-user temporary directory
    that numba is told about (override)."""
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    writable = {str(tmp_path / "xdg" / "numba")}
    monkeypatch.setattr(_jit, "_writable", lambda d: d in writable)
    _jit.cache_dir.cache_clear()
    try:
        assert _jit.cache_dir.__wrapped__() == (str(tmp_path / "xdg" / "numba"), False)
        writable.clear()
        directory, override = _jit.cache_dir.__wrapped__()
    finally:
        _jit.cache_dir.cache_clear()
    assert override and os.path.basename(directory).startswith("taut-numba-cache-")


def test_bad_mode_is_one_line_from_the_cli():
    env = dict(os.environ, TAUT_NUMBA="sometimes")
    out = subprocess.run([sys.executable, "-m", "taut", "fk", str(EXAMPLE1)], env=env,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 2
    assert out.stderr.strip() == ("taut: error: TAUT_NUMBA: must be one of auto, always, "
                                  "never, got 'sometimes'")
    out = _run("import taut._jit", None, "sometimes")
    assert out.returncode == 1 and "InvalidInputError: TAUT_NUMBA: must be one of" in out.stderr
    assert issubclass(InvalidInputError, ValueError)


def test_cold_process_answers_with_numpy_and_starts_one_warmup(tmp_path):
    """Empty cache, TAUT_NUMBA=auto: no numba in the process, the FK answer as compiled,
    one detached warmup started (a second process does not start another)."""
    code = ("import json, sys; import taut._jit as j; from taut.sheet import "
            "forward_kinematics; from taut.io import load_sheet_scenario; "
            f"sc = load_sheet_scenario({str(EXAMPLE1)!r}); "
            "r = forward_kinematics(sc.team, sc.formation); "
            "print(json.dumps([j.HAVE_NUMBA, 'numba' in sys.modules, "
            "[e.taut for e in r.equilibria], [list(e.object) for e in r.equilibria]]))")
    try:
        have, loaded, taut_sets, objects = json.loads(_python(code, tmp_path, "auto"))
        locks = list(tmp_path.glob("taut-jit-*.lock"))
        assert len(locks) == 1
        pid = int(locks[0].read_text())
        mtime = locks[0].stat().st_mtime_ns
        _python(code, tmp_path, "auto")
        assert [p.stat().st_mtime_ns for p in tmp_path.glob("taut-jit-*.lock")] == [mtime]
    finally:
        for lock in tmp_path.glob("taut-jit-*.lock"):
            try:
                os.killpg(int(lock.read_text()), signal.SIGTERM)   # the warmup we started
            except (OSError, ValueError):
                pass
    assert pid > 0 and not have and not loaded
    from taut.io import load_sheet_scenario
    from taut.sheet import FKSolver
    sc = load_sheet_scenario(EXAMPLE1)
    ref = FKSolver(sc.team, backend="numba").solve(sc.formation)
    assert taut_sets == [list(e.taut) for e in ref.equilibria]
    assert np.allclose(objects, [e.object for e in ref.equilibria], rtol=0, atol=1e-9)


def test_compile_stops_the_warmup_its_own_import_started(tmp_path):
    """`taut compile` on a cold cache imports taut._jit, which starts a background warmup;
    compile_kernels stops that one (and frees its lock) before compiling in the
    foreground, so the kernels are not compiled twice at once."""
    code = ("import json, os, taut._jit as j\n"
            "child = j._started[0]\n"
            "lock = j.stamp_path() + '.lock'\n"
            "before = os.path.exists(lock)\n"
            "j._stop_own_warmup()\n"
            "print(json.dumps([before, os.path.exists(lock), child.poll() is not None, "
            "len(j._started)]))\n")
    assert json.loads(_python(code, tmp_path, "auto")) == [True, False, True, 0]
    assert not list(tmp_path.glob("taut-jit-*.stamp"))


def test_numba_backend_on_a_cold_cache_says_why(tmp_path):
    code = ("import taut.sheet as ts\n"
            "team = ts.SheetTeam(ts.Sheet.regular(4, 1.0), 1.0)\n"
            "try:\n    ts.FKSolver(team, backend='numba')\n"
            "except Exception as e:\n    print(type(e).__name__, e)\n")
    # a fresh lock: the process believes a warmup is running and starts none
    stamp = _python("import taut._jit as j; print(j.stamp_path())", tmp_path, "never")
    Path(stamp.strip() + ".lock").write_text("0")
    out = _python(code, tmp_path, "auto")
    assert out.startswith("InvalidInputError backend: the compiled kernels are not in the "
                          "cache yet")
    out = _python(code, tmp_path, "never")
    assert "disabled by TAUT_NUMBA=never" in out


def test_per_call_front_end_loads_numba_only_once_worth_it(tmp_path):
    """forward_kinematics answers with numpy until its calls have cost LOAD_COST_S, then
    with the compiled solver; the answers are the same."""
    code = ("import json, sys; import taut._jit as j, taut.sheet as ts\n"
            "team = ts.SheetTeam(ts.Sheet.regular(5, 1.0), 1.0, mass=1.0)\n"
            "f = 0.8 * team.sheet.vertices; f[0] += 0.05\n"
            "a = ts.forward_kinematics(team, f)\n"
            "first = 'numba' in sys.modules\n"
            "j.charge_numpy(j.LOAD_COST_S)\n"
            "b = ts.forward_kinematics(team, f)\n"
            "print(json.dumps([first, 'numba' in sys.modules, "
            "[[e.taut, list(e.object), list(e.weights)] for e in a.equilibria], "
            "[[e.taut, list(e.object), list(e.weights)] for e in b.equilibria]]))")
    first, later, a, b = json.loads(_python(code, None, "always"))
    assert (first, later) == (False, True)
    assert [x[0] for x in a] == [x[0] for x in b] and a
    flat = [np.concatenate([x[1] + x[2] for x in r]) for r in (a, b)]
    assert np.allclose(flat[0], flat[1], rtol=0, atol=1e-9)


@pytest.mark.slow
def test_warmup_compiles_what_the_commands_use(tmp_path):
    """After the warmup (the install step), `taut fk` and `taut plan` compile nothing
    (numba saves no new machine code) and run compiled; the plan is the same as with
    the numpy fallback (the planning kernels as plain Python)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), TAUT_NUMBA="auto")
    subprocess.run([sys.executable, "-m", "taut", "compile"], env=env, check=True,
                   timeout=1800)
    assert len(list(tmp_path.glob("taut-jit-*.stamp"))) == 1
    assert not list(tmp_path.glob("taut-jit-*.lock"))        # no second, background warmup
    root = Path(__file__).parent.parent
    plan = [sys.executable, "-m", "taut", "plan", "examples/plan/paper_corridor.yaml",
            "--json"]
    for cmd in ([sys.executable, "-m", "taut", "fk", str(EXAMPLE1)], plan):
        out = subprocess.run(cmd, env=dict(env, NUMBA_DEBUG_CACHE="1"), cwd=root,
                             capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr
        assert "data saved" not in out.stdout + out.stderr
    compiled = subprocess.run(plan, env=env, cwd=root, capture_output=True, text=True,
                              timeout=600, check=True).stdout
    plain = subprocess.run(plan, env=dict(env, TAUT_NUMBA="never"), cwd=root,
                           capture_output=True, text=True, timeout=1200, check=True).stdout
    _assert_close(json.loads(compiled), json.loads(plain))


def _assert_close(a, b, path="plan"):
    """Same JSON tree; numbers equal within 1e-9 (the compiled and the plain kernels
    round differently: e.g. -1.8e-16 against -2.7e-16 for a coordinate that is 0)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), path
        for key in a:
            _assert_close(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _assert_close(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert abs(a - b) <= 1e-9 * max(1.0, abs(a)), (path, a, b)
    else:
        assert a == b, (path, a, b)


def test_warmup_byte_compiles_every_module(tmp_path):
    """`taut compile` (the warmup) also writes the package's bytecode, as pip does for a
    wheel, so the first command after it compiles no module: every module of a copy
    without ``__pycache__`` gets the file import reads (``cache_from_source``)."""
    import importlib.util

    from taut import _warmup

    pkg = tmp_path / "taut"
    shutil.copytree(SRC, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    sources = sorted(pkg.rglob("*.py"))
    assert len(sources) > 100 and not list(pkg.rglob("*.pyc"))
    assert _warmup.bytecode(str(pkg))
    missing = [p for p in sources if not Path(importlib.util.cache_from_source(str(p))).is_file()]
    assert not missing, missing[:5]
    assert _warmup.warm.__code__.co_names.count("bytecode") == 1     # the warmup calls it
