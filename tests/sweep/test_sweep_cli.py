"""`taut sweep`: run, resume, plot, and one-line errors with exit code 2."""

import pytest

from cli_calls import run

SPEC = """task: fk_stability_map
base: {base}
chunk_size: 8
parameters:
  scale: {{range: [0.6, 1.0], num: 4}}
  stretch_angle: [0, 60, 120]
  stretch: 1.2
"""


@pytest.fixture
def spec_file(tmp_path, examples_dir):
    path = tmp_path / "sweep.yaml"
    path.write_text(SPEC.format(base=examples_dir / "sheet" / "example2_r2_r4_353mm.yaml"))
    return path


def test_run_then_plot(capsys, spec_file, tmp_path):
    code, out, err = run(capsys, "sweep", spec_file, "--out", tmp_path / "res", "--workers", 0)
    assert code == 0 and "12 rows" in out
    code, out, err = run(capsys, "sweep", "plot", tmp_path / "res", "--x", "scale", "--y",
                         "stretch_angle", "--value", "n_stable")
    assert code == 0 and (tmp_path / "res" / "n_stable.png").stat().st_size > 1000
    code, out, err = run(capsys, "sweep", "plot", tmp_path / "res", "--x", "scale",
                         "--value", "feasible", "--out", tmp_path / "rate.svg")
    assert code == 0 and (tmp_path / "rate.svg").is_file()


def _one_error_line(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines and lines[-1].startswith("taut: error: ") and "Traceback" not in err
    return lines[-1]


@pytest.mark.parametrize("text,field", [
    ("task: nope\nparameters: {a: 1}\n", "task"),
    ("task: plan_suite\nparameters: {seeds: [1]}\n", "parameters.seeds"),
    ("task: plan_suite\nparameters: {scenario_seed: {range: [3, 1], num: 2}}\n",
     "parameters.scenario_seed.range"),
    ("task: plan_suite\n", "parameters"),
    ("[1, 2]\n", "sweep.yaml"),
])
def test_bad_sweep_files_exit_2_naming_the_field(capsys, tmp_path, text, field):
    path = tmp_path / "sweep.yaml"
    path.write_text(text)
    code, out, err = run(capsys, "sweep", path, "--out", tmp_path / "res", "--workers", 0)
    assert code == 2
    line = _one_error_line(err)
    assert field in line


def test_bad_run_options_exit_2(capsys, spec_file, tmp_path):
    for args, field in ((("--workers", -1), "--workers"), (("--limit", 0), "--limit")):
        code, _, err = run(capsys, "sweep", spec_file, "--out", tmp_path / "r", *args)
        assert code == 2 and field in _one_error_line(err)
    (tmp_path / "file").write_text("x")
    code, _, err = run(capsys, "sweep", spec_file, "--out", tmp_path / "file", "--workers", 0)
    assert code == 2 and "out:" in _one_error_line(err)


def test_plot_errors(capsys, spec_file, tmp_path):
    code, _, err = run(capsys, "sweep", "plot", tmp_path, "--x", "scale", "--value", "n_stable")
    assert code == 2 and "results.parquet" in _one_error_line(err)
    run(capsys, "sweep", spec_file, "--out", tmp_path / "res", "--workers", 0)
    code, _, err = run(capsys, "sweep", "plot", tmp_path / "res", "--x", "scael",
                       "--value", "n_stable")
    assert code == 2 and "--x" in _one_error_line(err)
    code, _, err = run(capsys, "sweep", "plot", tmp_path / "res", "--x", "scale",
                       "--value", "n_stable", "--out", tmp_path / "fig.bmp")
    assert code == 2 and "--out" in _one_error_line(err)


def test_rerun_without_resume_is_refused_and_resume_finishes(capsys, spec_file, tmp_path):
    run(capsys, "sweep", spec_file, "--out", tmp_path / "res", "--workers", 0, "--limit", 5)
    code, _, err = run(capsys, "sweep", spec_file, "--out", tmp_path / "res", "--workers", 0)
    assert code == 2 and "--resume" in _one_error_line(err)
    code, out, _ = run(capsys, "sweep", spec_file, "--out", tmp_path / "res", "--workers", 0,
                       "--resume")
    assert code == 0 and "12 rows" in out and "1 reused" in out
