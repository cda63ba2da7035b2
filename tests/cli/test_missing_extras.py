"""A missing optional extra is named at its real call site (issue 24, item 6): the import
itself is made to fail (``sys.modules[name] = None`` makes ``import name`` raise, as when
the package is not installed) and the real command or library entry point runs. The CLI
prints one line naming the extra and exits 2 before any work; the API raises a
:class:`~taut.errors.TautError` naming it (:class:`~taut.errors.MissingExtraError` for
MuJoCo, Dask and Starlette)."""

import sys
from pathlib import Path

import numpy as np
import pytest

from taut.cli import main
from taut.errors import MissingExtraError, TautError

ROOT = Path(__file__).parents[2]
SHEET = ROOT / "examples" / "sheet" / "example1.yaml"
CORRIDOR = ROOT / "examples" / "plan" / "paper_corridor.yaml"
SWEEP = ROOT / "examples" / "sweeps" / "octagon_stability_small.yaml"


def block(monkeypatch, *modules):
    """Make ``import m`` fail for each module (and forget the app's server module, which
    imports Starlette when it is itself imported)."""
    for m in modules:
        # A submodule an earlier test in this process imported is found in sys.modules
        # without its package being looked up: block those too.
        for name in [n for n in sys.modules if n == m or n.startswith(m + ".")]:
            monkeypatch.setitem(sys.modules, name, None)
        monkeypatch.setitem(sys.modules, m, None)
    monkeypatch.delitem(sys.modules, "taut.app.server", raising=False)
    # ``from ..app import server`` also finds the submodule as an attribute of its package
    # when an earlier test in this process imported it: forget that too.
    app = sys.modules.get("taut.app")
    if app is not None:
        monkeypatch.delattr(app, "server", raising=False)


def line(module, extra):
    return (f"taut: error: {module}: not installed; install taut[{extra}] "
            f"(pip install 'taut[{extra}]')\n")


@pytest.mark.parametrize("blocked, argv, expected", [
    (["mujoco"], ["physics", str(SHEET)], line("mujoco", "physics")),
    (["dask", "distributed"], ["sweep", "run", str(SWEEP), "--workers", "2", "--out", "{out}"],
     line("dask", "sweep")),
    (["distributed"], ["sweep", "run", str(SWEEP), "--workers", "2", "--out", "{out}"],
     line("distributed", "sweep")),
    (["starlette"], ["app", "--port", "0"], line("starlette", "app")),
    (["ompl"], ["plan", str(CORRIDOR), "--search", "ompl-rrtconnect"], None),
], ids=["physics", "sweep-dask", "sweep-distributed", "app", "plan-ompl"])
def test_the_command_names_the_missing_extra(monkeypatch, tmp_path, capsys, blocked, argv,
                                             expected):
    """The real command, its extra's import failing: one line, exit 2, nothing written."""
    block(monkeypatch, *blocked)
    out = tmp_path / "out"
    assert main([a.format(out=out) for a in argv]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    if expected is None:                     # OMPL: named through the option that needs it
        assert captured.err.startswith("taut: error: --search: ")
        assert "install 'taut[plan-ompl]'" in captured.err
    else:
        assert captured.err == expected
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err
    assert not out.exists()                  # refused before the sweep's folder is made


def _sheet():
    from taut.io.sheet_scenario import load_sheet_scenario
    sc = load_sheet_scenario(SHEET)
    return sc.team, sc.formation


def _fastkit():
    from taut.io.cdpr_model import load_cdpr_model
    return load_cdpr_model("fastkit")


@pytest.mark.parametrize("call", [
    lambda: __import__("taut.physics", fromlist=["settle"]).settle(*_sheet()),
    lambda: __import__("taut.physics", fromlist=["x"]).replay_equilibria(*_sheet()),
    lambda: __import__("taut.physics", fromlist=["x"]).replay_tipping(
        _fastkit(), np.array([0, 0, 1.0, 0, 0, 0]), np.full(_fastkit().m, 100.0)),
    lambda: __import__("taut.physics", fromlist=["x"]).replay_tipping_grid(
        _fastkit(), np.array([[0, 0, 1.0, 0, 0, 0]])),
], ids=["settle", "replay_equilibria", "replay_tipping", "replay_tipping_grid"])
def test_physics_entry_points_raise_a_typed_error(monkeypatch, call):
    block(monkeypatch, "mujoco")
    with pytest.raises(MissingExtraError) as e:
        call()
    assert isinstance(e.value, TautError) and isinstance(e.value, ImportError)
    assert e.value.field == "mujoco" and e.value.extra == "physics"
    assert "install taut[physics]" in str(e.value)


def test_a_parallel_sweep_raises_a_typed_error_before_writing(monkeypatch, tmp_path):
    from taut.sweep import load_sweep, run_sweep
    sweep = load_sweep(SWEEP)
    block(monkeypatch, "dask", "distributed")
    with pytest.raises(MissingExtraError) as e:
        run_sweep(sweep, tmp_path / "out", workers=2)
    assert e.value.extra == "sweep"
    assert not list((tmp_path / "out").glob("chunks/*"))
    # the serial run needs no Dask
    assert run_sweep(sweep, tmp_path / "serial", workers=0, limit=8).success


def test_the_app_module_raises_a_typed_error(monkeypatch):
    """``import taut.app.server`` without Starlette: a MissingExtraError, which is also the
    ImportError such an import raises."""
    block(monkeypatch, "starlette")
    with pytest.raises(MissingExtraError) as e:
        import taut.app.server  # noqa: F401
    assert e.value.field == "starlette" and e.value.extra == "app"


def test_an_ompl_plan_raises_a_typed_error(monkeypatch):
    from taut.io.plan_scenario import load_plan_scenario
    from taut.plan import plan
    sc = load_plan_scenario(CORRIDOR)
    block(monkeypatch, "ompl")
    with pytest.raises(TautError) as e:
        plan(sc, search="ompl-rrtconnect")
    assert e.value.field == "search" and "taut[plan-ompl]" in e.value.problem


@pytest.mark.parametrize("module", ["mujoco", "dask", "distributed", "pyarrow", "starlette",
                                    "uvicorn", "ompl", "matplotlib"])
def test_the_line_names_the_extra_of_pyproject(module):
    """The module -> extra map names extras that pyproject.toml declares and that list
    the module."""
    import tomllib
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    err = MissingExtraError(module)
    assert err.extra in extras, err.extra
    listed = " ".join(extras[err.extra]).lower()
    assert module.replace("_", "-") in listed or (module == "ompl" and "ompl" in listed)
