"""Sweeps in bounded memory: random draws made chunk by chunk equal the one-stream draws,
results.parquet is written in row groups from the chunks one at a time, and read back by
column, by row range and batch by batch with the same rows."""

import numpy as np
import pytest

from taut.errors import InvalidInputError
from taut.sweep import iter_results, read_results, results_columns, run_sweep
from taut.sweep import store as store_module
from taut.sweep.file import sweep_from_mapping
from taut.sweep.points import chunk_bounds, chunk_columns, expand

RANDOM = {"scale": {"uniform": [0.5, 1.0]}, "stretch_angle": {"integers": [0, 180]},
          "stretch": {"choice": [1.0, 1.3, 1.5]}, "rotation": {"normal": [0, 10]}}


def _random_spec(examples_dir, samples=101, chunk=16, seed=3):
    return sweep_from_mapping({"task": "fk_stability_map",
                               "base": "examples/sheet/example2_r2_r4_353mm.yaml",
                               "mode": "random", "samples": samples, "seed": seed,
                               "chunk_size": chunk, "parameters": RANDOM},
                              examples_dir.parent)


def _one_stream(spec):
    """The definition of random mode: one generator, each parameter's draws in file order."""
    rng = np.random.default_rng(spec.seed)
    return {p.name: p.sample(rng, spec.size) for p in spec.parameters}


@pytest.mark.parametrize("chunk", [1, 7, 16, 100, 101])
def test_random_chunks_are_slices_of_the_one_stream(examples_dir, chunk):
    spec = _random_spec(examples_dir)
    whole = _one_stream(spec)
    bounds = chunk_bounds(spec.size, chunk)
    for (lo, hi), cols in zip(bounds, chunk_columns(spec, bounds)):
        np.testing.assert_array_equal(cols["point"], np.arange(lo, hi))
        piece = expand(spec, lo, hi)
        for name, values in whole.items():
            np.testing.assert_array_equal(cols[name], values[lo:hi])
            np.testing.assert_array_equal(piece[name], values[lo:hi])


def test_random_chunks_out_of_order_and_with_gaps(examples_dir):
    spec = _random_spec(examples_dir)
    whole = _one_stream(spec)
    bounds = [(40, 50), (0, 5), (90, 101), (95, 101)]
    for (lo, hi), cols in zip(bounds, chunk_columns(spec, bounds)):
        for name, values in whole.items():
            np.testing.assert_array_equal(cols[name], values[lo:hi])


def test_grid_chunks_equal_expand(fk_spec):
    spec = fk_spec(scale={"range": [0.6, 1.0], "num": 7}, stretch_angle=[0, 30, 60])
    bounds = chunk_bounds(spec.size, 4)
    got = list(chunk_columns(spec, bounds))
    full = expand(spec)
    for name in full:
        np.testing.assert_array_equal(np.concatenate([c[name] for c in got]), full[name])


@pytest.fixture
def small_groups(monkeypatch):
    monkeypatch.setattr(store_module, "ROW_GROUP_ROWS", 10)


def test_results_are_written_in_row_groups_and_read_back_by_rows_and_columns(
        examples_dir, tmp_path, small_groups, same_rows):
    import pyarrow.parquet as pq
    spec = _random_spec(examples_dir, samples=57, chunk=4)
    res = run_sweep(spec, tmp_path / "run", workers=0, limit=53)
    assert res.success and res.rows == 53
    meta = pq.ParquetFile(res.path).metadata
    assert meta.num_rows == 53 and [meta.row_group(g).num_rows for g in range(6)] == \
        [10, 10, 10, 10, 10, 3]
    whole, info = read_results(tmp_path / "run")
    np.testing.assert_array_equal(whole["point"], np.arange(53))
    for name, values in _one_stream(spec).items():
        np.testing.assert_array_equal(whole[name], values[:53])
    names, meta2, n = results_columns(tmp_path / "run")
    assert names == list(whole) and meta2 == info and n == 53
    for lo, hi in [(0, 53), (0, 0), (11, 12), (12, 13), (7, 31), (50, 53)]:
        part, _ = read_results(tmp_path / "run", columns=["lowest_height", "point"],
                               rows=(lo, hi))
        assert list(part) == ["lowest_height", "point"]
        same_rows(part, {k: whole[k][lo:hi] for k in part})
    batches = list(iter_results(tmp_path / "run", columns=["point", "lowest_taut"],
                                batch_rows=8))
    assert all(len(b["point"]) <= 8 for b in batches)
    same_rows({k: np.concatenate([b[k] for b in batches]) for k in batches[0]},
              {k: whole[k] for k in ("point", "lowest_taut")})


@pytest.mark.parametrize("kw, field", [
    ({"columns": ["nope"]}, "columns"), ({"columns": "point"}, "columns"),
    ({"rows": (5, 2)}, "rows"), ({"rows": (0, 10**6)}, "rows"), ({"rows": 3}, "rows")])
def test_bad_reads_name_the_field(fk_spec, tmp_path, kw, field):
    run_sweep(fk_spec(scale=[0.8, 0.9]), tmp_path / "run", workers=0)
    with pytest.raises(InvalidInputError) as err:
        read_results(tmp_path / "run", **kw)
    assert err.value.field == field
