"""Sweep files: validation with field-named errors, and the points they describe."""

import numpy as np
import pytest

from taut.errors import SweepError
from taut.sweep import sweep_from_mapping
from taut.sweep.points import chunk_bounds, expand, point_seeds

BASE = {"task": "plan_suite", "parameters": {"scenario_seed": [1, 2, 3]}}


def _spec(**over):
    data = {**BASE, **over}
    return sweep_from_mapping({k: v for k, v in data.items() if v is not None})


@pytest.mark.parametrize("over,field", [
    ({"task": "fk_stabilty_map"}, "task"),
    ({"parameters": {"scenario_sed": 1}}, "parameters.scenario_sed"),
    ({"parameters": {"scenario_seed": {"range": [5, 1], "num": 3}}}, "parameters.scenario_seed.range"),
    ({"parameters": {"scenario_seed": []}}, "parameters.scenario_seed"),
    ({"parameters": {"scenario_seed": True}}, "parameters.scenario_seed"),
    ({"parameters": {"scenario_seed": {"range": [0, 1], "step": 0}}}, "parameters.scenario_seed.step"),
    ({"parameters": {"scenario_seed": {"range": [0, 1]}}}, "parameters.scenario_seed"),
    ({"parameters": {"scenario_seed": float("nan")}}, "parameters.scenario_seed"),
    ({"parameters": {}}, "parameters"),
    ({"outputs": ["sucess"]}, "outputs[0]"),
    ({"mode": "random"}, "samples"),
    ({"mode": "sparse"}, "mode"),
    ({"seed": -1}, "seed"),
    ({"frobnicate": 1}, "frobnicate"),
    ({"base": "x.yaml"}, "base"),
    ({"parameters": {"scenario_seed": {"uniform": [0, 1]}}}, "parameters.scenario_seed"),
    ({"mode": "random", "samples": 5, "parameters": {"scenario_seed": {"uniform": [3, 3]}}},
     "parameters.scenario_seed.uniform"),
    ({"parameters": {"scenario_seed": {"range": [0, 1e9], "step": 1e-3}}},
     "parameters.scenario_seed.step"),
])
def test_bad_sweep_files_name_the_field(over, field):
    with pytest.raises(SweepError) as err:
        _spec(**over)
    assert err.value.field == field


def test_fk_task_needs_its_base_file():
    with pytest.raises(SweepError) as err:
        sweep_from_mapping({"task": "fk_stability_map", "parameters": {"scale": 1}})
    assert err.value.field == "base"


def test_grid_is_the_cartesian_product_first_parameter_slowest():
    spec = _spec(parameters={"scenario_seed": {"range": [0, 2], "num": 3},
                             "n_robots": [3, 4]})
    cols = expand(spec)
    assert spec.size == 6
    np.testing.assert_array_equal(cols["scenario_seed"], [0, 0, 1, 1, 2, 2])
    np.testing.assert_array_equal(cols["n_robots"], [3, 4, 3, 4, 3, 4])
    np.testing.assert_array_equal(cols["point"], np.arange(6))


def test_step_ranges_include_the_end_when_it_falls_on_a_step():
    spec = _spec(parameters={"scenario_seed": {"range": [0, 180], "step": 18}})
    np.testing.assert_allclose(expand(spec)["scenario_seed"], np.arange(0, 181, 18))


@pytest.mark.parametrize("chunk", [1, 3, 7, 50])
def test_slices_and_seeds_do_not_depend_on_chunking(chunk):
    spec = sweep_from_mapping({"task": "plan_robustness", "base": "examples/plan/paper_corridor.yaml",
                               "mode": "random", "samples": 23, "seed": 4,
                               "parameters": {"sigma": {"uniform": [0, 0.01]}}})
    full = expand(spec)
    pieces = [expand(spec, lo, hi) for lo, hi in chunk_bounds(spec.size, chunk)]
    np.testing.assert_array_equal(np.concatenate([p["point"] for p in pieces]), full["point"])
    seeds = point_seeds(spec, full["point"])
    again = np.concatenate([point_seeds(spec, p["point"]) for p in pieces])
    np.testing.assert_array_equal(seeds, again)
    assert len(set(seeds.tolist())) == spec.size


def test_digest_changes_with_what_changes_results():
    a = _spec()
    assert a.digest == _spec().digest
    assert a.digest != _spec(parameters={"scenario_seed": [1, 2, 4]}).digest
    assert a.digest != _spec(seed=1).digest


CDPR = {"task": "cdpr_workspace", "base": "fastkit", "parameters": {"payload": [0.0]}}


def _cdpr(**over):
    return sweep_from_mapping({**CDPR, **over})


@pytest.mark.parametrize("over,field", [
    ({"seed": True}, "seed"), ({"chunk_size": False}, "chunk_size"),
    ({"mode": "random", "samples": True, "parameters": {"payload": {"uniform": [0, 1]}}},
     "samples"),
    ({"parameters": {"payload": [0.0, True]}}, "parameters.payload[1]"),
    ({"parameters": {"payload": {"range": [0, True], "num": 3}}}, "parameters.payload.range[1]"),
    ({"parameters": {"payload": {"range": [0, 1], "num": True}}}, "parameters.payload.num"),
    ({"parameters": {"payload": {"range": [0, 1], "step": True}}}, "parameters.payload.step"),
    ({"parameters": {"payload": {"values": [False]}}}, "parameters.payload.values[0]"),
    ({"mode": "random", "samples": 3, "parameters": {"payload": {"normal": [0, True]}}},
     "parameters.payload.normal[1]"),
    ({"options": {"grid": [2, True, 2]}}, "options.grid[1]"),
    ({"options": {"box": [[0, 0, 0], [1, True, 1]]}}, "options.box[1][1]"),
    ({"parameters": {"payload": "1.5"}}, "parameters.payload"),
    ({"parameters": {"payload": {"range": [0, 1], "num": 2.0}}}, "parameters.payload.num"),
    ({"parameters": {"payload": {"range": [0, 1], "nun": 2}}}, "parameters.payload.nun"),
    ({"outputs": [3]}, "outputs[0]"),
    ({"base": 3}, "base"),
])
def test_a_boolean_or_string_is_no_number_anywhere(over, field):
    # Strict numbers in the file's model itself: no second walk over the data.
    with pytest.raises(SweepError) as err:
        _cdpr(**over)
    assert err.value.field == field


def test_integers_are_numbers_and_floats_keep_their_value():
    spec = _cdpr(parameters={"payload": {"range": [0, 10], "num": 3},
                             "base_separation": [5, 6.5]},
                 options={"grid": [2, 1, 2], "box": [[-1, 0, 0], [1, 0, 1.5]]})
    np.testing.assert_array_equal(spec.parameters[0].values, [0.0, 5.0, 10.0])
    np.testing.assert_array_equal(spec.parameters[1].values, [5.0, 6.5])
    assert spec.parameters[1].values.dtype == np.float64
    assert spec.options == {"grid": [2, 1, 2], "box": [[-1.0, 0.0, 0.0], [1.0, 0.0, 1.5]]}
