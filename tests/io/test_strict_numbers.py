"""One validation path (issue 32): every file kind's numbers are pydantic's strict types
(taut.io.files.Number / Integer), so a boolean (or a string) where the file has a number is
refused by the model itself, named by its dotted key, with no second walk over the data."""

import copy
from pathlib import Path
from typing import Any, Callable

import pytest
from hypothesis import given, strategies as st

from taut.errors import ScenarioError, TautError
from taut.io import (cdpr_model_from_mapping, parse_mapping, plan_scenario_from_mapping,
                     read_mapping, sheet_scenario_from_mapping, validate_mapping,
                     warehouse_from_mapping)
from taut.io.cdpr_dynamics import dynamics_from_mapping
from taut.io.cdpr_model import preset_path
from taut.io.robot_trajectories import robot_trajectories_from_mapping
from taut.sweep import sweep_from_mapping

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _sheet() -> dict[str, Any]:
    data = read_mapping(EXAMPLES / "sheet" / "example2_r2_r4_353mm.yaml")
    data.update(mass=0.5, object={"radius": 40})          # every optional number present
    return data


def _plan_with_polygon() -> dict[str, Any]:
    """The paper corridor with an explicit sheet and a polygon obstacle with a numeric id
    (the example has a regular team and round obstacles only)."""
    data = read_mapping(EXAMPLES / "plan" / "paper_corridor.yaml")
    data["team"].pop("regular")
    data["team"]["sheet"] = [[0, 0], [1, 0], [0.5, 0.8]]
    data["obstacles"].append({"id": 3, "height": 0.1,
                              "polygon": [[3, 0.5], [3.2, 0.5], [3.2, 0.7]]})
    return data


def _model() -> dict[str, Any]:
    data = read_mapping(preset_path("fastkit"))
    data["bases"][0]["friction"] = 0.5
    return data


def _trajectories() -> dict[str, Any]:
    """A robot-trajectories JSON file (``taut plan --trajectories t.json``), every summary
    number set."""
    return {"success": True, "status": "ok", "message": "m", "drive": "differential",
            "duration_s": 1.0, "plan_duration_s": 0.8, "turns_in_place": 1,
            "limits": {"max_speed_mps": 0.2, "max_accel_mps2": 0.5,
                       "max_yaw_rate_radps": 1.0, "reform_speed_mps": 0.05},
            "peaks": {"speed_mps": 0.1, "accel_mps2": 0.2, "yaw_rate_radps": 0.3},
            "times_s": [0.0, 0.5, 1.0],
            "poses_m_rad": [[[0.0, 0.0, 0.1], [1.0, 0.0, 0.2]] for _ in range(3)],
            "object_m": [[0.5, 0.0, 0.3] for _ in range(3)]}


def _sweep(name: str) -> Callable[[dict[str, Any]], Any]:
    return lambda data: sweep_from_mapping(data, root=EXAMPLES / "sweeps")


#: (file kind, a complete file, its loader); dynamics sections are loaded on their own
#: too (their errors are named ``dynamics.<key>``).
KINDS: list[tuple[str, Callable[[], dict[str, Any]], Callable[[dict[str, Any]], Any]]] = [
    ("sheet scenario", _sheet, sheet_scenario_from_mapping),
    ("plan scenario", lambda: read_mapping(EXAMPLES / "plan" / "paper_corridor.yaml"),
     plan_scenario_from_mapping),
    ("plan scenario, sheet and polygon", _plan_with_polygon, plan_scenario_from_mapping),
    ("cdpr model", _model, cdpr_model_from_mapping),
    ("dynamics section", lambda: {"dynamics": read_mapping(preset_path("fastkit"))["dynamics"]},
     lambda data: dynamics_from_mapping(data["dynamics"])),
    ("warehouse", lambda: read_mapping(EXAMPLES / "cdpr" / "warehouse.yaml"),
     lambda data: warehouse_from_mapping(data, EXAMPLES / "cdpr")),
    ("sweep, grid", lambda: read_mapping(EXAMPLES / "sweeps" / "octagon_stability.yaml"),
     _sweep("grid")),
    ("sweep, random", lambda: read_mapping(EXAMPLES / "sweeps" / "corridor_robustness.yaml"),
     _sweep("random")),
    ("sweep, options", lambda: read_mapping(EXAMPLES / "sweeps" / "fastkit_coverage.yaml"),
     _sweep("options")),
    ("robot trajectories", _trajectories, robot_trajectories_from_mapping),
]


def _numbers(data: Any, loc: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Locations of every number (not a boolean) in parsed file data."""
    if isinstance(data, bool):
        return []
    if isinstance(data, (int, float)):
        return [loc]
    items = data.items() if isinstance(data, dict) else \
        enumerate(data) if isinstance(data, list) else ()
    return [where for k, v in items for where in _numbers(v, loc + (k,))]


def _field(loc: tuple[Any, ...]) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else ("." if i else "") + str(p)
                   for i, p in enumerate(loc))


def _replace(data: dict[str, Any], loc: tuple[Any, ...], value: Any) -> dict[str, Any]:
    out = copy.deepcopy(data)
    node: Any = out
    for part in loc[:-1]:
        node = node[part]
    node[loc[-1]] = value
    return out


@pytest.mark.parametrize("kind, make, load", KINDS, ids=[k[0] for k in KINDS])
def test_every_file_kind_loads_and_has_numbers(kind, make, load):
    """The bases the property test edits are valid files with numbers to replace."""
    data = make()
    load(data)
    assert len(_numbers(data)) >= 3


@pytest.mark.parametrize("kind, make, load", KINDS, ids=[k[0] for k in KINDS])
@given(pick=st.integers(min_value=0), flag=st.booleans(), as_text=st.booleans())
def test_a_boolean_or_string_for_any_number_is_refused_naming_it(kind, make, load, pick,
                                                                 flag, as_text):
    """Any number of any file kind replaced by ``true``/``false`` (or the number as a
    string, which pydantic's lax floats read as a number) is an error naming that key."""
    data = make()
    places = _numbers(data)
    loc = places[pick % len(places)]
    as_text = as_text and loc[-1] != "id"            # an obstacle id may be a string
    bad: Any = str(_at(data, loc)) if as_text else flag
    with pytest.raises(TautError) as err:
        load(_replace(data, loc, bad))
    assert err.value.field == _field(loc), (kind, loc, str(err.value))
    if not as_text:
        assert err.value.problem == "must be a number, got a boolean"


def _at(data: Any, loc: tuple[Any, ...]) -> Any:
    for part in loc:
        data = data[part]
    return data


def test_integers_are_numbers_and_booleans_stay_booleans():
    """An integer where a float is expected is read as that float; a boolean field still
    takes a boolean (only numbers are strict)."""
    data = _sheet()
    data["hold_height"] = 800
    assert sheet_scenario_from_mapping(data).team.hold_height == 800.0
    model = _model()
    model["bases"][0]["stabilisers"]["deployed"] = True
    assert cdpr_model_from_mapping(model).bases[0].stabilisers_deployed is True


def test_free_form_data_is_validated_at_any_depth_without_recursion():
    """A model with a free-form field (``Any``) accepts data nested as deep as the parser
    allows (700 levels here; no walk of taut's follows it), and a boolean in a strict
    number list is named at its first location."""
    from pydantic import BaseModel

    from taut.io.files import Number

    class Model(BaseModel):
        x: list[Number] = []
        free: Any = None

    deep = parse_mapping('{"free": ' + "[" * 700 + "true" + "]" * 700 + "}", "f",
                         suffix=".json")
    assert validate_mapping(Model, deep).x == []
    with pytest.raises(ScenarioError) as err:
        validate_mapping(Model, {"free": [True], "x": [1.0, True, False]})
    assert err.value.field == "x[1]" and err.value.problem == "must be a number, got a boolean"
