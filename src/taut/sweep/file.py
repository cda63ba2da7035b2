"""Sweep files (YAML or JSON): what to compute, over which parameters, keeping what.

```yaml
task: fk_stability_map              # a name in taut.sweep.TASKS
base: ../sheet/example2_r2_r4_353mm.yaml   # scenario/model file (relative to this file)
                                    # or a cdpr preset name ("fastkit")
mode: grid                          # grid (Cartesian product, default) or random
seed: 0                             # random draws and per-point noise (>= 0)
samples: 1000                       # number of points, random mode only
chunk_size: 2048                    # points per task (optional; the task's default)
parameters:
  scale: {range: [0.6, 1.0], num: 41}       # num values, ends included
  stretch_angle: {range: [0, 180], step: 5} # lo, lo + step, ... up to hi
  stretch: 1.3                              # one value (also [1.1, 1.3]: a list)
  jitter: {uniform: [0, 5]}                 # random mode: uniform, normal, integers, choice
outputs: [n_stable, lowest_height]  # optional subset of the task's outputs
options: {grid: [21, 1, 9]}         # task options that are not swept
```

``options`` are checked per task (:data:`TASK_OPTIONS`): ``cdpr_workspace`` and
``cdpr_deployment`` take ``box`` ([[xmin, ymin, zmin], [xmax, ymax, zmax]], m) and ``grid``
(three integers nx ny nz >= 1, points per axis of the box); the other tasks take none.

Every mistake is a :class:`~taut.errors.SweepError` naming the key (``parameters.scale``,
``options.grid[0]``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np

from .._validate import MAX_CDPR_LENGTH_M, as_path
from ..errors import SweepError
from ..io.files import read_mapping, read_text
from .registry import TASKS
from .spec import DISTRIBUTIONS, Parameter, SweepSpec, _choice

__all__ = ["load_sweep", "sweep_from_mapping", "base_model"]

_KEYS = {"task", "base", "mode", "seed", "samples", "chunk_size", "parameters", "outputs",
         "options", "name"}
#: Most points one sweep may hold (a grid's product or random samples).
MAX_POINTS = 10**9
#: Most values one grid axis may hold.
MAX_AXIS = 10**7
#: Most points of a task's workspace grid (``options.grid``), per sweep point.
MAX_GRID_POINTS = 10**6

#: Options each task accepts (name -> meaning with unit); tasks not listed take none.
TASK_OPTIONS: dict[str, dict[str, str]] = {
    task: {"box": "workspace box [[xmin, ymin, zmin], [xmax, ymax, zmax]], m (default: "
                  "the model's desired workspace)",
           "grid": "grid points per axis of the box [nx, ny, nz] (default [21, 1, 9])"}
    for task in ("cdpr_workspace", "cdpr_deployment")}


def _number(value: Any, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SweepError(field, f"must be a number, got {value!r}")
    if not np.isfinite(value):
        raise SweepError(field, "must be finite")
    return float(value)


def _count(value: Any, field: str, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise SweepError(field, f"must be an integer, got {value!r}")
    if not low <= value <= high:
        raise SweepError(field, f"must be in [{low}, {high}], got {value}")
    return int(value)


def _grid_values(value: Any, field: str) -> np.ndarray:
    if isinstance(value, Mapping):
        extra = set(value) - {"range", "num", "step", "values"}
        if extra:
            raise SweepError(f"{field}.{sorted(extra)[0]}", "unknown key")
        if "values" in value:
            return _grid_values(value["values"], f"{field}.values")
        if "range" not in value:
            raise SweepError(field, "needs range: [low, high] with num or step, or values")
        rng = value["range"]
        if not isinstance(rng, list) or len(rng) != 2:
            raise SweepError(f"{field}.range", "must be [low, high]")
        lo, hi = (_number(v, f"{field}.range") for v in rng)
        if hi < lo:
            raise SweepError(f"{field}.range", f"is empty: high {hi:g} < low {lo:g}")
        if ("num" in value) == ("step" in value):
            raise SweepError(field, "give exactly one of num and step with range")
        if "num" in value:
            num = _count(value["num"], f"{field}.num", 1, MAX_AXIS)
            return np.linspace(lo, hi, num)
        step = _number(value["step"], f"{field}.step")
        if step <= 0:
            raise SweepError(f"{field}.step", "must be > 0")
        if (hi - lo) / step >= MAX_AXIS:
            raise SweepError(f"{field}.step", f"makes more than {MAX_AXIS} values")
        num = int(np.floor((hi - lo) / step * (1 + 1e-12))) + 1
        return lo + step * np.arange(num)
    if isinstance(value, list):
        if not value:
            raise SweepError(field, "is an empty list")
        return np.array([_number(v, f"{field}[{i}]") for i, v in enumerate(value)])
    return np.array([_number(value, field)])


def _options(value: Any, task: str) -> dict[str, Any]:
    """The ``options`` mapping checked against :data:`TASK_OPTIONS` (plain lists kept)."""
    if not isinstance(value, Mapping):
        raise SweepError("options", "must be a mapping")
    known = TASK_OPTIONS.get(task, {})
    for key in value:
        if key not in known:
            expected = (f"expected one of {', '.join(known)}" if known else
                        f"task {task} takes no options")
            raise SweepError(f"options.{key}", f"unknown option; {expected}")
    out: dict[str, Any] = {}
    if value.get("grid") is not None:
        grid = value["grid"]
        if not isinstance(grid, list) or len(grid) != 3:
            raise SweepError("options.grid", "must be three integers [nx, ny, nz]")
        counts = [_count(g, f"options.grid[{k}]", 1, MAX_GRID_POINTS)
                  for k, g in enumerate(grid)]
        if int(np.prod(counts)) > MAX_GRID_POINTS:
            raise SweepError("options.grid", f"makes more than {MAX_GRID_POINTS} points")
        out["grid"] = counts
    if value.get("box") is not None:
        box = value["box"]
        if not (isinstance(box, list) and len(box) == 2
                and all(isinstance(r, list) and len(r) == 3 for r in box)):
            raise SweepError("options.box", "must be [[xmin, ymin, zmin], [xmax, ymax, "
                                            "zmax]], m")
        rows = [[_number(v, f"options.box[{i}][{k}]") for k, v in enumerate(r)]
                for i, r in enumerate(box)]
        for i, r in enumerate(rows):
            for k, v in enumerate(r):
                if abs(v) > MAX_CDPR_LENGTH_M:
                    raise SweepError(f"options.box[{i}][{k}]", f"|value| {v:g} exceeds the "
                                     f"accepted range {MAX_CDPR_LENGTH_M:g} m")
        if any(lo > hi for lo, hi in zip(*rows)):
            raise SweepError("options.box", "min must be <= max on every axis")
        out["box"] = rows
    return out


def _parameter(name: str, value: Any, mode: str) -> Parameter:
    field = f"parameters.{name}"
    if isinstance(value, Mapping) and set(value) & set(DISTRIBUTIONS):
        if mode != "random":
            raise SweepError(field, "random distributions need mode: random")
        if len(value) != 1:
            raise SweepError(field, "give one distribution")
        (law, args), = value.items()
        if not isinstance(args, list):
            raise SweepError(f"{field}.{law}", "must be a list of numbers")
        nums = [_number(v, f"{field}.{law}[{i}]") for i, v in enumerate(args)]
        return Parameter(name, distribution=law, arguments=np.array(nums))
    if mode == "random":
        values = _grid_values(value, field)
        if values.size != 1:
            raise SweepError(field, "in random mode give a distribution or one value")
        return Parameter(name, distribution="choice", arguments=values)
    return Parameter(name, values=_grid_values(value, field))


def _base(data: Mapping[str, Any], task: str, root: Path
          ) -> tuple[str | None, dict[str, Any] | None]:
    need = TASKS[task].needs_base
    base = data.get("base")
    if not need:
        if base is not None:
            raise SweepError("base", f"task {task} takes no base file")
        return None, None
    if not isinstance(base, str) or not base:
        raise SweepError("base", f"required: the {need} to sweep (a file path)")
    if need == "cdpr model" and "/" not in base and "." not in base:
        return base, None                             # a preset name
    path = (root / base).resolve()
    mapping = read_mapping(path)
    _BUILDERS[need](mapping)                          # validate now, on the client
    return str(path), mapping


def base_model(spec: SweepSpec) -> Any:
    """The sweep's base scenario or model, built from the parsed file in the spec (or the
    preset), so that a worker needs no access to the file; None for a task without one."""
    need = TASKS[spec.task].needs_base
    if not need:
        return None
    if spec.base_data is None:
        from ..io.cdpr_model import load_cdpr_model
        return load_cdpr_model(str(spec.base))
    return _BUILDERS[need](dict(spec.base_data))


def _sheet(data: dict[str, Any]) -> Any:
    from ..io.sheet_scenario import sheet_scenario_from_mapping
    return sheet_scenario_from_mapping(data)


def _plan(data: dict[str, Any]) -> Any:
    from ..io.plan_scenario import plan_scenario_from_mapping
    return plan_scenario_from_mapping(data)


def _cdpr(data: dict[str, Any]) -> Any:
    from ..io.cdpr_model import cdpr_model_from_mapping
    return cdpr_model_from_mapping(data)


_BUILDERS = {"sheet scenario": _sheet, "plan scenario": _plan, "cdpr model": _cdpr}


def sweep_from_mapping(data: Mapping[str, Any], root: str | Path = ".",
                       source: str = "") -> SweepSpec:
    """Validate a parsed sweep file; relative ``base`` paths are resolved from ``root``.

    Parameters
    ----------
    data : mapping
        The sweep file's top level (see the module docstring).
    root : path
        Folder that relative ``base`` paths start from.
    source : str
        The file's text, kept in the results' metadata.

    Returns
    -------
    SweepSpec

    Raises
    ------
    SweepError
        Any invalid key or value, naming it.
    """
    if not isinstance(data, Mapping):
        raise SweepError("data", f"must be a mapping of sweep keys, got {type(data).__name__}")
    folder = as_path(root, "root")
    if not isinstance(source, str):
        raise SweepError("source", f"must be the file's text (str), got {type(source).__name__}")
    unknown = {str(k) for k in data} - _KEYS
    if unknown:
        raise SweepError(sorted(unknown)[0], "unknown key")
    task = _choice(data.get("task"), sorted(TASKS), "task")
    spec_task = TASKS[task]
    mode = cast(Literal["grid", "random"],
                _choice(data.get("mode", "grid"), ("grid", "random"), "mode"))
    seed = _count(data.get("seed", 0), "seed", 0, 2**63 - 1)
    samples = 0
    if mode == "random":
        samples = _count(data.get("samples"), "samples", 1, MAX_POINTS) \
            if "samples" in data else 0
        if not samples:
            raise SweepError("samples", "required in random mode: the number of points")
    elif "samples" in data:
        raise SweepError("samples", "only in random mode")
    params_in = data.get("parameters")
    if not isinstance(params_in, Mapping) or not params_in:
        raise SweepError("parameters", "required: a mapping of parameter names to values")
    params = []
    for name, value in params_in.items():
        if name not in spec_task.parameters:
            raise SweepError(f"parameters.{name}", f"unknown parameter of {task}; expected "
                             f"one of {', '.join(spec_task.parameters)}")
        params.append(_parameter(str(name), value, mode))
    outputs = data.get("outputs", [])
    if not isinstance(outputs, list):
        raise SweepError("outputs", "must be a list of output names")
    for k, name in enumerate(outputs):
        if not isinstance(name, str) or name not in spec_task.outputs:
            raise SweepError(f"outputs[{k}]", f"unknown output {name!r} of {task}; expected "
                             f"one of {', '.join(spec_task.outputs)}")
    chunk = _count(data.get("chunk_size", 0), "chunk_size", 0, 10**7)
    options = _options(data.get("options", {}), task)
    base, base_data = _base(data, task, folder)
    spec = SweepSpec(task=task, parameters=tuple(params), base=base, base_data=base_data,
                     mode=mode, samples=samples, seed=seed, chunk_size=chunk,
                     outputs=tuple(outputs), options=dict(options), source=source)
    if spec.size > MAX_POINTS:
        raise SweepError("parameters", f"make {spec.size} points, more than {MAX_POINTS}")
    return spec


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep file (YAML or JSON).

    Raises
    ------
    SweepError
        Any invalid key or value, naming it.
    ScenarioError
        A missing, unreadable or malformed file.
    """
    p = as_path(path)
    data = read_mapping(p)
    return sweep_from_mapping(data, p.parent, read_text(p))
