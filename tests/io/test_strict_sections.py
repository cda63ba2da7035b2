"""Strict schemas for every section of every file kind (issue 24, "one safe loader for
every file": no free-form ``dict[str, Any]``).

Two halves:

* the shapes, walked programmatically: every pydantic model of a file loader (taut.io and
  the sweep file) forbids unknown keys, no field anywhere holds ``Any``, the only mappings
  keyed by the user's own names are the three listed in :data:`NAMED_MAPPINGS`, and every
  model is reachable from one of the file kinds' top-level models (none forgotten);
* the behaviour, on the shipped files: an unknown key injected into each section of each
  example input file (and preset model) is refused by that file kind's loader with a
  :class:`~taut.errors.TautError` whose field is the injected key's dotted path.

CASPR models are XML read element by element (tests/io/test_loaders.py); trajectory CSV
files are rows of numbers under a fixed header (tests/io/test_hostile_trajectory.py). No
robot-trajectories JSON file is shipped: a small one is built here (values:
tests/io/test_robot_trajectories_file.py).
"""

from __future__ import annotations

import copy
import inspect
import types
import typing
from pathlib import Path
from typing import Any, Annotated, Callable, Literal, Union

import pytest
import yaml
from pydantic import BaseModel

from taut.errors import TautError
from taut.io import (cdpr_model_from_mapping, plan_scenario_from_mapping, read_mapping,
                     sheet_scenario_from_mapping, warehouse_from_mapping)
from taut.io import (cdpr_dynamics, cdpr_model, plan_scenario, robot_trajectories,
                     sheet_scenario, warehouse)
from taut.io.cdpr_dynamics import dynamics_from_mapping
from taut.io.cdpr_model import PRESETS, preset_path
from taut.sweep import file as sweep_file
from taut.sweep import sweep_from_mapping

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
UNKNOWN = "zz_not_a_key"

#: The top-level model of each file kind (and of a model's dynamics section on its own,
#: as ``taut cdpr simulate`` reads it).
ROOTS: dict[str, type[BaseModel]] = {
    "sheet scenario": sheet_scenario._SheetScenarioFile,
    "plan scenario": plan_scenario._PlanFile,
    "cdpr model": cdpr_model._ModelFile,
    "cdpr dynamics": cdpr_dynamics._Section,
    "warehouse": warehouse._WarehouseFile,
    "sweep": sweep_file._SweepFile,
    "robot trajectories": robot_trajectories._TrajectoriesFile,
}

#: The modules that define file models (every module of taut.io that uses pydantic, and
#: the sweep file's).
MODULES = [sheet_scenario, plan_scenario, cdpr_model, cdpr_dynamics, warehouse, sweep_file,
           robot_trajectories]

#: Mappings whose keys are names the user chooses (points, parameters), not schema keys:
#: ``(model, field)`` -> what the keys are. Their values are still typed.
NAMED_MAPPINGS = {
    ("_Base", "exit_points"): "exit point names",
    ("_Platform", "attachment_points"): "attachment point names",
    ("_SweepFile", "parameters"): "swept parameter names (checked against the task)",
}


# --- the shapes ------------------------------------------------------------------------

def _inner(tp: Any) -> list[Any]:
    """The types directly inside ``tp`` (Annotated metadata and Literal values left out)."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return [typing.get_args(tp)[0]]
    if origin is Literal:
        return []
    return [a for a in typing.get_args(tp) if a is not Ellipsis]


def _leaves(tp: Any) -> list[Any]:
    """Every type anywhere inside an annotation (``tp`` included)."""
    out = [tp]
    for a in _inner(tp):
        out += _leaves(a)
    return out


def _is_model(tp: Any) -> bool:
    return inspect.isclass(tp) and issubclass(tp, BaseModel)


def _models_under(model: type[BaseModel], seen: set | None = None) -> set[type[BaseModel]]:
    seen = set() if seen is None else seen
    if model in seen:
        return seen
    seen.add(model)
    for f in model.model_fields.values():
        for leaf in _leaves(f.annotation):
            if _is_model(leaf):
                _models_under(leaf, seen)
    return seen


REACHABLE = set().union(*(_models_under(m) for m in ROOTS.values()))
DEFINED = {obj for mod in MODULES for obj in vars(mod).values()
           if _is_model(obj) and obj is not BaseModel and obj.__module__ == mod.__name__}


def test_every_file_model_is_reachable_from_a_file_kind():
    """No model outside the walk below (a new section is walked as soon as it exists)."""
    unused = {m for m in DEFINED - REACHABLE            # shared bases (model_config only)
              if m.model_fields or not any(issubclass(r, m) for r in REACHABLE)}
    assert unused == set(), "models no file kind uses"
    assert len(REACHABLE) >= 20


@pytest.mark.parametrize("model", sorted(REACHABLE | DEFINED,
                                         key=lambda m: (m.__qualname__, m.__module__)),
                         ids=lambda m: f"{m.__module__.rsplit('.', 1)[1]}.{m.__qualname__}")
def test_every_model_forbids_unknown_keys_and_holds_no_any(model):
    assert model.model_config.get("extra") == "forbid", f"{model.__qualname__} is not strict"
    for name, f in model.model_fields.items():
        leaves = _leaves(f.annotation)
        assert Any not in leaves and object not in leaves, \
            f"{model.__qualname__}.{name}: {f.annotation} holds Any"
        for leaf in leaves:       # a bare dict or list would be free-form too
            assert leaf not in (dict, list, typing.Dict, typing.List), \
                f"{model.__qualname__}.{name}: {f.annotation} has an untyped container"


def test_the_only_mappings_keyed_by_user_names_are_listed():
    found = {(m.__name__, name) for m in REACHABLE for name, f in m.model_fields.items()
             if any(typing.get_origin(t) is dict for t in _leaves(f.annotation))}
    assert found == set(NAMED_MAPPINGS)


# --- the behaviour, on the shipped files -------------------------------------------------

def _sections(value: Any, tp: Any, path: tuple) -> list[tuple[tuple, type]]:
    """``(path, model)`` of every mapping in ``value`` that a model (a section) validates,
    following the annotation ``tp`` alongside the data."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return _sections(value, typing.get_args(tp)[0], path)
    if origin in (Union, types.UnionType):
        options = [a for a in typing.get_args(tp) if a is not type(None)]
        if isinstance(value, dict):
            models = [m for a in options for m in _leaves(a) if _is_model(m)]
            fits = [m for m in models if set(value) <= set(m.model_fields)]
            return _sections(value, fits[0], path) if fits else []
        out: list[tuple[tuple, type]] = []
        for a in options:
            if typing.get_origin(a) in (list, tuple) or typing.get_origin(a) is Annotated:
                out = out or _sections(value, a, path)
        return out
    if _is_model(tp) and isinstance(value, dict):
        out = [(path, tp)]
        for name, f in tp.model_fields.items():
            if name in value:
                out += _sections(value[name], f.annotation, path + (name,))
        return out
    if origin is dict and isinstance(value, dict):
        item = typing.get_args(tp)[1]
        return [p for k, v in value.items() for p in _sections(v, item, path + (k,))]
    if origin in (list, tuple) and isinstance(value, list):
        args = [a for a in typing.get_args(tp) if a is not Ellipsis]
        return [p for i, v in enumerate(value)
                for p in _sections(v, args[i] if origin is tuple and len(args) > 1 else args[0],
                                   path + (i,))]
    return []


def _dotted(path: tuple) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else ("." if out else "") + str(part)
    return out


def _rel(p: Path) -> str:
    return str(p.relative_to(ROOT))


def _sweep(path: Path) -> Callable[[dict], Any]:
    return lambda data: sweep_from_mapping(data, root=path.parent)


def _warehouse(path: Path) -> Callable[[dict], Any]:
    return lambda data: warehouse_from_mapping(data, path.parent)


def _trajectories() -> dict[str, Any]:
    """A robot-trajectories JSON file as ``taut plan --trajectories t.json`` writes it
    (two samples of two robots; an unset limit is ``null``)."""
    return {"success": True, "status": "ok", "message": "m", "drive": "holonomic",
            "duration_s": 1.0, "plan_duration_s": 1.0, "turns_in_place": 0,
            "limits": {"max_speed_mps": 0.2, "max_accel_mps2": 0.5,
                       "max_yaw_rate_radps": 1.0, "reform_speed_mps": None},
            "peaks": {"speed_mps": 0.1, "accel_mps2": 0.2, "yaw_rate_radps": 0.0},
            "times_s": [0.0, 1.0],
            "poses_m_rad": [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
                            [[0.1, 0.0, 0.0], [1.1, 0.0, 0.0]]],
            "object_m": [[0.5, 0.0, 0.3], [0.6, 0.0, 0.3]]}


def _inputs() -> list[tuple[str, str, Callable[[], dict], Callable[[dict], Any]]]:
    """(file, kind, its data, its loader) for every shipped input file."""
    out: list[tuple[str, str, Callable[[], dict], Callable[[dict], Any]]] = []
    for p in sorted((EXAMPLES / "sheet").rglob("*.yaml")):
        out.append((_rel(p), "sheet scenario", lambda p=p: read_mapping(p),
                    sheet_scenario_from_mapping))
    for p in sorted((EXAMPLES / "plan").glob("*.yaml")):
        out.append((_rel(p), "plan scenario", lambda p=p: read_mapping(p),
                    plan_scenario_from_mapping))
    for p in sorted((EXAMPLES / "sweeps").glob("*.yaml")):
        out.append((_rel(p), "sweep", lambda p=p: read_mapping(p), _sweep(p)))
    # sections no shipped file has: a sheet scenario's object, a random sweep's law
    sheet2 = EXAMPLES / "sheet" / "example2_r2_r4_353mm.yaml"
    out.append((_rel(sheet2) + " + object", "sheet scenario",
                lambda: dict(read_mapping(sheet2), object={"radius": 40.0}),
                sheet_scenario_from_mapping))
    corridor = EXAMPLES / "sweeps" / "corridor_robustness.yaml"
    out.append((_rel(corridor) + " + random", "sweep",
                lambda: dict(read_mapping(corridor), mode="random", samples=4,
                             parameters={"sigma": {"uniform": [0.0, 0.01]},
                                         "trial": {"integers": [0, 999]}}),
                _sweep(corridor)))
    wh = EXAMPLES / "cdpr" / "warehouse.yaml"
    out.append((_rel(wh), "warehouse", lambda: read_mapping(wh), _warehouse(wh)))
    out.append(("built robot trajectories", "robot trajectories", _trajectories,
                robot_trajectories.robot_trajectories_from_mapping))
    for name in PRESETS:
        out.append((f"preset {name}", "cdpr model",
                    lambda name=name: read_mapping(preset_path(name)),
                    cdpr_model_from_mapping))
        if "dynamics" in read_mapping(preset_path(name)):
            out.append((f"preset {name}, dynamics", "cdpr dynamics",
                        lambda name=name: {"dynamics": read_mapping(preset_path(name))
                                           ["dynamics"]},
                        lambda data: dynamics_from_mapping(data["dynamics"])))
    return out


INPUTS = _inputs()


def test_every_shipped_yaml_file_is_an_input_here():
    """Every YAML file under examples/ is one of the inputs below, and each loads as is
    (so a refusal below is the injected key's)."""
    listed = {name for name, *_ in INPUTS}
    assert {_rel(p) for p in EXAMPLES.rglob("*.yaml")} <= listed
    assert {kind for _, kind, *_ in INPUTS} == set(ROOTS)
    for name, _, data, load in INPUTS:
        load(data())


def _cases() -> list[Any]:
    cases = []
    for name, kind, data, load in INPUTS:
        for path, model in _sections(data(), ROOTS[kind], ()):
            if kind == "cdpr dynamics" and path == ():
                continue                    # the wrapper {"dynamics": ...} is not a file
            cases.append(pytest.param(data, load, path,
                                      id=f"{name}:{_dotted(path) or '(top)'}"))
    return cases


CASES = _cases()


def test_the_injections_reach_every_model():
    """Every section model of every file kind gets an unknown key below (a model not in
    the shipped files is in one of the completed files of :func:`_inputs`)."""
    hit = {model for _, kind, data, _ in INPUTS for _, model in _sections(data(), ROOTS[kind], ())}
    assert hit == REACHABLE


@pytest.mark.parametrize("data, load, path", CASES)
def test_an_unknown_key_in_any_section_is_refused_naming_it(data, load, path):
    d = copy.deepcopy(data())
    node: Any = d
    for part in path:
        node = node[part]
    node[UNKNOWN] = 1
    with pytest.raises(TautError) as err:
        load(d)
    assert err.value.field == _dotted(path + (UNKNOWN,)), str(err.value)
    assert "unknown" in err.value.problem


def test_a_command_refuses_an_unknown_dynamics_key_of_its_model(tmp_path, capsys):
    """The model's ``dynamics:`` section was a mapping of any names, checked only by the
    commands that simulate: ``taut cdpr tensions`` ran with a misspelt key. Now every
    command that loads the model refuses it, in one line naming it."""
    from taut.cli import main

    data = read_mapping(preset_path("fastkit"))
    data["dynamics"]["cable_stifness"] = 1e5                      # misspelt
    path = tmp_path / "model.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["cdpr", "tensions", str(path), "--pose", "0", "0", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dynamics.cable_stifness: unknown key" in err, err
