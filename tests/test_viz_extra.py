"""matplotlib is the `viz` extra: every solver package imports without it, and a figure
request without it is refused in one line naming the extra (exit 2, no traceback).

Each check runs in a fresh interpreter whose import system refuses matplotlib (a meta path
finder raising ModuleNotFoundError, as a missing install does)."""

import subprocess
import sys
import textwrap

import pytest

BLOCK = textwrap.dedent("""
    import sys
    class NoMatplotlib:
        def find_spec(self, name, path=None, target=None):
            if name == "matplotlib" or name.startswith("matplotlib."):
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None
    sys.meta_path.insert(0, NoMatplotlib())
""")


def _python(code: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", BLOCK + textwrap.dedent(code)], cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def test_the_blocker_blocks():
    run = _python("import matplotlib")
    assert run.returncode != 0 and "ModuleNotFoundError" in run.stderr


def test_every_solver_package_imports_without_matplotlib():
    run = _python("""
        import taut, taut.sheet, taut.plan, taut.cdpr, taut.sweep, taut.io, taut.physics
        from taut.sheet import forward_kinematics
        import taut.sweep.runner, taut.sweep.tasks
        assert not any(m == "matplotlib" or m.startswith("matplotlib.") for m in sys.modules)
        print("ok")
    """)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr


@pytest.fixture
def sweep_folder(tmp_path, examples_dir):
    pytest.importorskip("pyarrow")
    from taut.sweep import run_sweep, sweep_from_mapping
    spec = sweep_from_mapping({"task": "fk_stability_map",
                               "base": "examples/sheet/example2_r2_r4_353mm.yaml",
                               "parameters": {"scale": [0.8, 0.9]}}, examples_dir.parent)
    run_sweep(spec, tmp_path / "sweep", workers=0)
    return tmp_path / "sweep"


@pytest.mark.parametrize("argv", [
    ["fk", "examples/sheet/example1.yaml", "--plot", "{tmp}/fig/fk.png"],
    ["sweep", "plot", "{tmp}/sweep", "--x", "scale", "--value", "n_stable",
     "--out", "{tmp}/fig/map.png"],
])
def test_a_figure_request_without_matplotlib_names_the_extra(argv, tmp_path, examples_dir,
                                                             sweep_folder):
    (tmp_path / "fig").mkdir()
    argv = [a.format(tmp=tmp_path) for a in argv]
    run = _python(f"""
        from taut.cli import main
        sys.exit(main({argv!r}))
    """, cwd=examples_dir.parent)
    errors = [line for line in run.stderr.splitlines() if "error" in line.lower()]
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert errors == ["taut: error: matplotlib: not installed; install taut[viz] "
                      "(pip install 'taut[viz]')"]
    assert not list((tmp_path / "fig").iterdir())
