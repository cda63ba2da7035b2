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

The file's shape is a pydantic model like every other file kind's (strict numbers: a
boolean or a string is not a number), validated by :func:`taut.io.files.validate_mapping`;
what the shape cannot say (the task's parameter, output and option names, the mode's rules,
ranges and sizes) is checked after it. Every mistake is a :class:`~taut.errors.SweepError`
naming the key (``parameters.scale``, ``options.grid[0]``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal, Union, cast

import numpy as np
from pydantic import Discriminator, Field, Strict, Tag

from .._validate import MAX_CDPR_LENGTH_M, MAX_WORKSPACE_POSES, as_path
from ..errors import ScenarioError, SweepError
from ..io.files import Integer, Number, StrictModel, read_mapping, read_text, validate_mapping
from .registry import TASKS
from .spec import DISTRIBUTIONS, Parameter, SweepSpec, _choice

__all__ = ["load_sweep", "sweep_from_mapping", "base_model"]

#: Most points one sweep may hold (a grid's product or random samples).
MAX_POINTS = 10**9
#: Most values one grid axis may hold.
MAX_AXIS = 10**7
#: Largest ``chunk_size`` (points per task): a chunk's rows are held in memory while it
#: is computed, ~1.9 kB a point (the FK octagon map, 8 outputs: 291 MB peak at chunks of
#: 5,000 points, 378 MB at 50,000; `/usr/bin/time`), so 10^5 points stay near 0.5 GB
#: (10^7, the former limit, would need ~19 GB).
MAX_CHUNK = 100_000

#: Options each task accepts (name -> meaning with unit); tasks not listed take none.
TASK_OPTIONS: dict[str, dict[str, str]] = {
    task: {"box": "workspace box [[xmin, ymin, zmin], [xmax, ymax, zmax]], m (default: "
                  "the model's desired workspace)",
           "grid": "grid points per axis of the box [nx, ny, nz] (default [21, 1, 9])"}
    for task in ("cdpr_workspace", "cdpr_deployment")}

# --- The file's shape, as pydantic models (strict: a boolean or a string is no number) ---

def _shape(value: Any) -> str:
    """Which form a parameter's value takes; the tags are the ones
    :func:`taut.io.files.validate_mapping` leaves out of an error's field."""
    if isinstance(value, Mapping):
        return "dict[law]" if set(value) & set(DISTRIBUTIONS) else "dict[axis]"
    return "list[float]" if isinstance(value, list) else "float"


class _Axis(StrictModel):
    """A grid axis: ``{range: [lo, hi], num: n}``, ``{range, step}`` or ``{values: [...]}``."""

    range: list[Number] | None = None
    num: Annotated[Integer, Field(ge=1, le=MAX_AXIS)] | None = None
    step: Number | None = None
    values: Annotated[list[Number], Field(min_length=1)] | None = None


class _Law(StrictModel):
    """A random distribution (random mode): one of its keys, with its numbers."""

    uniform: list[Number] | None = None
    normal: list[Number] | None = None
    integers: list[Number] | None = None
    choice: list[Number] | None = None


_Value = Annotated[Union[
    Annotated[Number, Tag("float")],
    Annotated[Annotated[list[Number], Field(min_length=1)], Tag("list[float]")],
    Annotated[_Axis, Tag("dict[axis]")],
    Annotated[_Law, Tag("dict[law]")]], Discriminator(_shape)]


class _Options(StrictModel):
    """Task options (every option any task takes; an unknown key is refused here, which
    of them a task takes is checked against :data:`TASK_OPTIONS`)."""

    grid: list[Annotated[Integer, Field(ge=1, le=MAX_WORKSPACE_POSES)]] | None = None
    box: list[list[Number]] | None = None


class _SweepFile(StrictModel):
    task: Annotated[str, Strict()]
    base: Annotated[str, Strict()] | None = None
    mode: Literal["grid", "random"] = "grid"
    seed: Annotated[Integer, Field(ge=0, le=2**63 - 1)] = 0
    samples: Annotated[Integer, Field(ge=1, le=MAX_POINTS)] | None = None
    chunk_size: Annotated[Integer, Field(ge=0, le=MAX_CHUNK)] = 0
    parameters: dict[str, _Value]
    outputs: list[Annotated[str, Strict()]] = []
    options: _Options = _Options()
    name: Annotated[str, Strict()] | None = None


# --- What the shape cannot say: per-task names, mode rules, ranges ---

def _grid_values(value: Any, field: str) -> np.ndarray:
    if isinstance(value, _Axis):
        if value.values is not None:
            return np.array(value.values)
        if value.range is None:
            raise SweepError(field, "needs range: [low, high] with num or step, or values")
        if len(value.range) != 2:
            raise SweepError(f"{field}.range", "must be [low, high]")
        lo, hi = value.range
        if hi < lo:
            raise SweepError(f"{field}.range", f"is empty: high {hi:g} < low {lo:g}")
        if (value.num is None) == (value.step is None):
            raise SweepError(field, "give exactly one of num and step with range")
        if value.num is not None:
            return np.linspace(lo, hi, value.num)
        step = cast(float, value.step)
        if step <= 0:
            raise SweepError(f"{field}.step", "must be > 0")
        if (hi - lo) / step >= MAX_AXIS:
            raise SweepError(f"{field}.step", f"makes more than {MAX_AXIS} values")
        num = int(np.floor((hi - lo) / step * (1 + 1e-12))) + 1
        return lo + step * np.arange(num)
    return np.array(value if isinstance(value, list) else [value], dtype=float)


def _options(value: _Options, task: str) -> dict[str, Any]:
    """The ``options`` checked against :data:`TASK_OPTIONS` (plain lists kept)."""
    known = TASK_OPTIONS.get(task, {})
    for key in [k for k in _Options.model_fields if k in value.model_fields_set]:
        if key not in known:
            expected = (f"expected one of {', '.join(known)}" if known else
                        f"task {task} takes no options")
            raise SweepError(f"options.{key}", f"unknown option; {expected}")
    out: dict[str, Any] = {}
    if value.grid is not None:
        if len(value.grid) != 3:
            raise SweepError("options.grid", "must be three integers [nx, ny, nz]")
        if int(np.prod(value.grid)) > MAX_WORKSPACE_POSES:
            raise SweepError("options.grid", f"makes more than {MAX_WORKSPACE_POSES} points")
        out["grid"] = list(value.grid)
    if value.box is not None:
        rows = value.box
        if len(rows) != 2 or any(len(r) != 3 for r in rows):
            raise SweepError("options.box", "must be [[xmin, ymin, zmin], [xmax, ymax, "
                                            "zmax]], m")
        for i, r in enumerate(rows):
            for k, v in enumerate(r):
                if abs(v) > MAX_CDPR_LENGTH_M:
                    raise SweepError(f"options.box[{i}][{k}]", f"|value| {v:g} exceeds the "
                                     f"accepted range {MAX_CDPR_LENGTH_M:g} m")
        if any(lo > hi for lo, hi in zip(*rows)):
            raise SweepError("options.box", "min must be <= max on every axis")
        out["box"] = [list(r) for r in rows]
    return out


def _parameter(name: str, value: Any, mode: str) -> Parameter:
    field = f"parameters.{name}"
    if isinstance(value, _Law):
        if mode != "random":
            raise SweepError(field, "random distributions need mode: random")
        laws = {k: v for k, v in value if v is not None}
        if len(laws) != 1:
            raise SweepError(field, "give one distribution")
        (law, args), = laws.items()
        return Parameter(name, distribution=law, arguments=np.array(args, dtype=float))
    values = _grid_values(value, field)
    if mode == "random":
        if values.size != 1:
            raise SweepError(field, "in random mode give a distribution or one value")
        return Parameter(name, distribution="choice", arguments=values)
    return Parameter(name, values=values)


def _base(base: str | None, task: str, root: Path
          ) -> tuple[str | None, dict[str, Any] | None]:
    need = TASKS[task].needs_base
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
    try:
        raw = validate_mapping(_SweepFile, dict(data))
    except ScenarioError as exc:
        raise SweepError(exc.field, exc.problem) from None
    task = _choice(raw.task, sorted(TASKS), "task")
    spec_task = TASKS[task]
    if raw.mode == "random" and not raw.samples:
        raise SweepError("samples", "required in random mode: the number of points")
    if raw.mode == "grid" and raw.samples is not None:
        raise SweepError("samples", "only in random mode")
    if not raw.parameters:
        raise SweepError("parameters", "required: a mapping of parameter names to values")
    params = []
    for name, value in raw.parameters.items():
        if name not in spec_task.parameters:
            raise SweepError(f"parameters.{name}", f"unknown parameter of {task}; expected "
                             f"one of {', '.join(spec_task.parameters)}")
        params.append(_parameter(name, value, raw.mode))
    for k, out in enumerate(raw.outputs):
        if out not in spec_task.outputs:
            raise SweepError(f"outputs[{k}]", f"unknown output {out!r} of {task}; expected "
                             f"one of {', '.join(spec_task.outputs)}")
    options = _options(raw.options, task)
    base, base_data = _base(raw.base, task, folder)
    spec = SweepSpec(task=task, parameters=tuple(params), base=base, base_data=base_data,
                     mode=raw.mode, samples=raw.samples or 0, seed=raw.seed,
                     chunk_size=raw.chunk_size, outputs=tuple(raw.outputs),
                     options=options, source=source)
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
