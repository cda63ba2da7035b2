"""Sweeps that cannot mix or silently lose (issue 24): one writer per folder (a lock naming
its holder), checksummed chunks with a damaged one recomputed on resume (and named, with
why), a damaged
results file a one-line error, ``options:`` validated per task, and two different sweeps
started together on one folder: one runs, the other is refused."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from taut.cli import main
from taut.errors import SweepError
from taut.sweep import read_results, run_sweep, sweep_from_mapping
from taut.sweep.store import Store

EXAMPLE2 = "examples/sheet/example2_r2_r4_353mm.yaml"

ROOT = Path(__file__).parents[2]
TAUT = Path(sys.executable).with_name("taut")


def test_a_second_writer_is_refused_naming_the_holder(fk_spec, tmp_path):
    spec = fk_spec(scale=[0.8, 0.9])
    with Store(tmp_path / "run", spec.digest, resume=False):
        with pytest.raises(SweepError) as err:
            run_sweep(spec, tmp_path / "run", workers=0)
        assert err.value.field == "out"
        assert f"process {os.getpid()}" in err.value.problem
    assert run_sweep(spec, tmp_path / "run", workers=0).success      # lock released
    assert not (tmp_path / "run" / ".lock").exists()


def test_a_stale_lock_of_a_dead_process_is_taken_over(fk_spec, tmp_path):
    import socket
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / ".lock").write_text(json.dumps(
        {"pid": dead.pid, "host": socket.gethostname(), "started": "earlier"}))
    assert run_sweep(fk_spec(scale=[0.8]), tmp_path / "run", workers=0).success


def test_two_different_sweeps_started_together_never_mix(tmp_path):
    """Two `taut sweep run` processes, different sweeps, one folder: exactly one
    writes, the other exits 2 naming the folder, and the results are the winner's."""
    specs = []
    for k, scale in enumerate(([0.7, 0.8, 0.9], [0.75, 0.85, 0.95])):
        path = tmp_path / f"s{k}.yaml"
        path.write_text(textwrap.dedent(f"""\
            task: fk_stability_map
            base: {ROOT / 'examples/sheet/example2_r2_r4_353mm.yaml'}
            chunk_size: 1
            parameters: {{scale: {scale}, stretch_angle: {{range: [0, 170], step: 10}}}}
            """))
        specs.append(path)
    out = tmp_path / "out"
    procs = [subprocess.Popen([str(TAUT), "sweep", "run", str(s), "--workers", "0",
                               "--out", str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for s in specs]
    results = [(p.wait(120), p.stderr.read()) for p in procs]
    codes = sorted(code for code, _ in results)
    assert codes == [0, 2], results
    loser = next(err for code, err in results if code == 2)
    assert "taut: error: out:" in loser and loser.count("\n") == 1
    cols, meta = read_results(out)
    winner = specs[[code for code, _ in results].index(0)]
    assert meta["sweep_source"] == winner.read_text()
    assert len(cols["point"]) == 54 and len(set(cols["scale"])) == 3


def test_a_damaged_chunk_is_recomputed_on_resume(tmp_path, same_rows):
    spec = sweep_from_mapping({"task": "fk_stability_map",
                               "base": "examples/sheet/example2_r2_r4_353mm.yaml",
                               "chunk_size": 3,
                               "parameters": {"scale": {"range": [0.6, 1.0], "num": 8}}},
                              ROOT)
    assert run_sweep(spec, tmp_path / "run", workers=0).success
    good, _ = read_results(tmp_path / "run")
    chunk = tmp_path / "run" / "chunks" / "chunk-0000001.parquet"
    chunk.write_bytes(chunk.read_bytes()[:100])             # truncated
    res = run_sweep(spec, tmp_path / "run", workers=0, resume=True)
    assert res.success and res.chunks_run == 1 and res.chunks_reused == 2
    assert res.damaged == (("chunk-0000001.parquet", "truncated"),)
    same_rows(read_results(tmp_path / "run")[0], good)
    # a flipped byte with the length kept is caught by the checksum too
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    res = run_sweep(spec, tmp_path / "run", workers=0, resume=True)
    assert res.success and res.chunks_run == 1
    assert res.damaged == (("chunk-0000001.parquet", "checksum mismatch"),)
    same_rows(read_results(tmp_path / "run")[0], good)


def test_resume_names_each_damaged_chunk_and_why(fk_spec, tmp_path, capsys, same_rows):
    """``taut sweep run --resume`` names every chunk it recomputes (file and reason) on
    stderr, one line each; chunks never written are only counted, and an intact folder
    gives no such line."""
    spec_file = tmp_path / "s.yaml"
    spec_file.write_text(textwrap.dedent(f"""\
        task: fk_stability_map
        base: {ROOT / 'examples/sheet/example2_r2_r4_353mm.yaml'}
        chunk_size: 2
        parameters: {{scale: {{range: [0.6, 1.0], num: 10}}}}
        """))
    out = tmp_path / "run"
    assert main(["sweep", "run", str(spec_file), "--out", str(out), "--workers", "0",
                 "--limit", "8"]) == 0                    # chunk 4 never written
    good, _ = read_results(out)
    chunks = out / "chunks"
    (chunks / "chunk-0000000.parquet").unlink()                          # missing
    (chunks / "chunk-0000001.parquet.sha256").unlink()                   # no checksum
    two = chunks / "chunk-0000002.parquet"
    two.write_bytes(two.read_bytes()[:-10])                              # truncated
    three = bytearray((chunks / "chunk-0000003.parquet").read_bytes())
    three[len(three) // 2] ^= 0xFF                                        # bytes changed
    (chunks / "chunk-0000003.parquet").write_bytes(bytes(three))
    capsys.readouterr()
    assert main(["sweep", "run", str(spec_file), "--out", str(out), "--workers", "0",
                 "--resume"]) == 0
    captured = capsys.readouterr()
    named = [line for line in captured.err.splitlines() if "recomputed" in line]
    assert named == ["taut: sweep: chunks/chunk-0000000.parquet recomputed (missing)",
                     "taut: sweep: chunks/chunk-0000001.parquet recomputed (no checksum)",
                     "taut: sweep: chunks/chunk-0000002.parquet recomputed (truncated)",
                     "taut: sweep: chunks/chunk-0000003.parquet recomputed "
                     "(checksum mismatch)"]
    assert "(5 chunks computed, 0 reused" in captured.out
    cols, _ = read_results(out)
    same_rows({k: v[:8] for k, v in cols.items()}, good)
    assert main(["sweep", "run", str(spec_file), "--out", str(out), "--workers", "0",
                 "--resume"]) == 0
    assert "recomputed" not in capsys.readouterr().err


def test_resume_names_at_most_ten_damaged_chunks_then_counts(tmp_path, capsys):
    """Past ``DAMAGED_NAMED`` damaged chunks, ``--resume`` names the first ten and counts
    the rest in one line (a folder of thousands of damaged chunks is not thousands of
    lines)."""
    from taut.cli.sweep import DAMAGED_NAMED

    spec_file = tmp_path / "s.yaml"
    spec_file.write_text(textwrap.dedent(f"""\
        task: fk_stability_map
        base: {ROOT / 'examples/sheet/example2_r2_r4_353mm.yaml'}
        chunk_size: 1
        parameters: {{scale: {{range: [0.6, 1.0], num: {DAMAGED_NAMED + 3}}}}}
        """))
    out = tmp_path / "run"
    assert main(["sweep", "run", str(spec_file), "--out", str(out), "--workers", "0"]) == 0
    for k in range(DAMAGED_NAMED + 3):
        (out / "chunks" / f"chunk-{k:07d}.parquet.sha256").unlink()
    capsys.readouterr()
    assert main(["sweep", "run", str(spec_file), "--out", str(out), "--workers", "0",
                 "--resume"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "recomputed" in line]
    assert len(lines) == DAMAGED_NAMED + 1
    assert lines[0] == "taut: sweep: chunks/chunk-0000000.parquet recomputed (no checksum)"
    assert lines[-1] == "taut: sweep: and 3 more damaged chunks recomputed"


def test_a_damaged_results_file_is_one_line_in_sweep_plot(fk_spec, tmp_path, capsys):
    spec = fk_spec(scale=[0.8, 0.9])
    run_sweep(spec, tmp_path / "run", workers=0)
    (tmp_path / "run" / "results.parquet").write_bytes(b"PAR1 not really")
    assert main(["sweep", "plot", str(tmp_path / "run"), "--x", "scale",
                 "--value", "n_stable"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("taut: error: folder: ") and "damaged" in err
    assert err.count("\n") == 1


@pytest.mark.parametrize("task, options, field", [
    ("cdpr_workspace", {"grid": "abc"}, "options.grid"),
    ("cdpr_workspace", {"grid": [2.7, 1, 1.9]}, "options.grid[0]"),     # was truncated
    ("cdpr_workspace", {"grid": [21, 0, 9]}, "options.grid[1]"),
    ("cdpr_workspace", {"grid": [True, 1, 1]}, "options.grid[0]"),
    ("cdpr_workspace", {"grid": [10**4, 10**4, 10]}, "options.grid"),
    ("cdpr_workspace", {"colour": 1}, "options.colour"),                # was accepted
    ("cdpr_workspace", {"box": [[0, 0, 0], [1, 1]]}, "options.box"),
    ("cdpr_workspace", {"box": [[0, 0, 0], [1, 1, "x"]]}, "options.box[1][2]"),
    ("cdpr_workspace", {"box": [[0, 0, 0], [1e300, 1, 1]]}, "options.box[1][0]"),
    ("cdpr_workspace", {"box": [[1, 0, 0], [0, 1, 1]]}, "options.box"),
    ("fk_stability_map", {"grid": [1, 1, 1]}, "options.grid"),
])
def test_options_are_validated_per_task(tmp_path, task, options, field):
    base = ("fastkit" if task.startswith("cdpr") else
            str(ROOT / "examples/sheet/example2_r2_r4_353mm.yaml"))
    params = {"payload": [1.0]} if task.startswith("cdpr") else {"scale": [1.0]}
    with pytest.raises(SweepError) as err:
        sweep_from_mapping({"task": task, "base": base, "parameters": params,
                            "options": options}, tmp_path)
    assert err.value.field == field


def test_valid_options_are_kept(tmp_path):
    spec = sweep_from_mapping({"task": "cdpr_workspace", "base": "fastkit",
                               "parameters": {"payload": [1.0]},
                               "options": {"grid": [3, 1, 2],
                                           "box": [[-1, 0, 0.5], [1, 0, 1.5]]}}, tmp_path)
    assert spec.options == {"grid": [3, 1, 2], "box": [[-1.0, 0.0, 0.5], [1.0, 0.0, 1.5]]}
    assert run_sweep(spec, tmp_path / "o", workers=0).rows == 1
    cols, _ = read_results(tmp_path / "o")
    assert np.all(np.isfinite(cols["coverage"]))


def test_sweep_plot_draws_every_documented_column(tmp_path, capsys):
    """Every output of the task, text columns (lowest_taut) as categories, as a curve and
    as a heat map."""
    from taut.sweep import TASKS
    spec = sweep_from_mapping({"task": "fk_stability_map",
                               "base": "examples/sheet/example2_r2_r4_353mm.yaml",
                               "parameters": {"scale": [0.7, 0.85, 1.0],
                                              "stretch_angle": [0, 60, 120]},
                               "options": {}}, ROOT)
    run_sweep(spec, tmp_path / "run", workers=0)
    cols, _ = read_results(tmp_path / "run")
    assert cols["lowest_taut"].dtype == object
    for value in TASKS["fk_stability_map"].outputs:
        heat = value in ("lowest_taut", "n_stable")          # a category and a count
        for extra in ([], ["--y", "stretch_angle"]) if heat else ([],):
            out = tmp_path / f"{value}{len(extra)}.png"
            code = main(["sweep", "plot", str(tmp_path / "run"), "--x", "scale",
                         "--value", value, "--out", str(out), *extra])
            assert code == 0, capsys.readouterr().err
            assert out.stat().st_size > 1000


def test_a_chunk_write_stops_when_the_folder_holds_another_sweeps_manifest(fk_spec,
                                                                           tmp_path):
    """The manifest is re-read on every chunk write: a folder handed to another sweep
    (its manifest replaced) stops this one at its next chunk, and nothing is written."""
    spec = fk_spec(scale=[0.8])
    cols = {"point": np.arange(2), "value": np.zeros(2)}
    with Store(tmp_path / "run", spec.digest, resume=False) as store:
        store.write_chunk(0, cols)
        (tmp_path / "run" / "manifest.json").write_text(
            json.dumps({"sweep_digest": "another"}) + "\n")
        with pytest.raises(SweepError) as err:
            store.write_chunk(1, cols)
        assert err.value.field == "out" and "another sweep's manifest" in err.value.problem
        assert not store.has(1) and store.has(0)


def test_a_sweep_of_too_many_chunks_is_refused_before_any_work(examples_dir, tmp_path,
                                                             monkeypatch):
    """10^9 points in chunks of one point made a list of 10^9 chunks before any work; a
    run of more than ``MAX_CHUNKS`` chunks is refused naming ``chunk_size`` and the
    smallest that fits, and ``--limit`` counts: only the chunks it reaches are listed."""
    from taut.sweep import runner
    monkeypatch.setattr(runner, "MAX_CHUNKS", 3)
    spec = sweep_from_mapping({"task": "fk_stability_map", "base": EXAMPLE2,
                               "chunk_size": 2,
                               "parameters": {"scale": {"range": [0.6, 1.0], "num": 7}}},
                              examples_dir.parent)
    with pytest.raises(SweepError) as err:
        run_sweep(spec, tmp_path / "run", workers=0)
    assert err.value.field == "chunk_size"
    assert "4 chunks, more than 3" in err.value.problem and "at least 3" in err.value.problem
    assert not (tmp_path / "run").exists()
    res = run_sweep(spec, tmp_path / "part", workers=0, limit=5)    # 3 chunks: accepted
    assert res.success and res.rows == 5
    assert len(list((tmp_path / "part" / "chunks").glob("*.parquet"))) == 3


def test_chunk_size_is_bounded_in_the_file(examples_dir):
    from taut.sweep.file import MAX_CHUNK
    with pytest.raises(SweepError) as err:
        sweep_from_mapping({"task": "fk_stability_map", "base": EXAMPLE2,
                            "chunk_size": MAX_CHUNK + 1, "parameters": {"scale": [0.8]}},
                           examples_dir.parent)
    assert err.value.field == "chunk_size"


@pytest.mark.parametrize("at", ["table", "rename", "hash", "checksum"])
def test_ctrl_c_inside_a_chunk_write_keeps_the_chunk_and_its_checksum(fk_spec, tmp_path,
                                                                     monkeypatch, at):
    """A Ctrl-C anywhere in a chunk's write (while Parquet writes it, at its rename, while
    it is hashed, while the checksum is written) still interrupts (KeyboardInterrupt, once
    the pair is written), and the chunk is there whole with its checksum: the resumed run
    takes it as finished. (Fresh-clone CI once kept a chunk without its checksum.)"""
    import hashlib
    import signal

    from taut.sweep import store as store_module

    def interrupted(fn, when):
        def wrapped(*args, **kw):
            if when(*args):
                signal.raise_signal(signal.SIGINT)      # Python's handler: KeyboardInterrupt
            return fn(*args, **kw)
        return wrapped

    target, when = {                # (the manifest's rewrite comes first: not that one)
        "table": ((store_module, "to_table"), lambda *a: True),
        "rename": ((store_module.os, "replace"), lambda src, dst: dst.name.endswith("quet")),
        "hash": ((store_module, "_sha256"), lambda *a: True),
        "checksum": ((Path, "write_text"), lambda path, *a: ".sha256" in path.name)}[at]
    spec = fk_spec(scale=[0.8, 0.9])
    # Python's own Ctrl-C handler: a shell starts a background job with SIGINT ignored,
    # and Python then installs none (so ran CI; raise_signal would do nothing).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with Store(tmp_path / "run", spec.digest, resume=False) as store:
            monkeypatch.setattr(*target, interrupted(getattr(*target), when))
            with pytest.raises(KeyboardInterrupt):
                store.write_chunk(0, {"x": np.arange(5.0)})
            monkeypatch.undo()
            stored = store.state(0)
            chunk = store.chunk_path(0)
    finally:
        signal.signal(signal.SIGINT, previous)
    if at == "table":                        # before the write began: nothing is written
        assert stored == "not computed"
        return
    assert stored == "finished"
    digest = Path(f"{chunk}.sha256").read_text().split()[0]
    assert hashlib.sha256(chunk.read_bytes()).hexdigest() == digest
