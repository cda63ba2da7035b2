"""Scenario and model files: load, validate, save. Solvers never import this package.

Files
    :func:`read_mapping` parses a YAML or JSON file whose top level is a mapping
    (:func:`parse_mapping` the same from text; files over :data:`MAX_FILE_BYTES`, YAML
    over :data:`MAX_YAML_CHARS` characters and alias bombs over :data:`MAX_YAML_VALUES`
    values refused), :func:`read_text` reads one, :func:`validate_mapping` checks a
    parsed mapping against a pydantic model (errors naming the dotted key), :func:`write_json` writes JSON,
    :func:`write_text_atomic` any text and :func:`atomic_path` gives a temporary file to
    write that replaces the target once complete (figures, animations).
Sheet scenarios
    :func:`load_sheet_scenario` and :func:`sheet_scenario_from_mapping` build a
    :class:`SheetScenario` (the team, its formation, the length unit).
Plan scenarios
    :func:`load_plan_scenario` and :func:`plan_scenario_from_mapping` build a
    :class:`taut.plan.Scenario`; :func:`plan_scenario_to_mapping` writes one back.
Cable-robot models
    :func:`load_cdpr_model` (a file or a preset name) and :func:`cdpr_model_from_mapping`
    build a :class:`taut.cdpr.CableRobot`.
Warehouses
    :func:`load_warehouse` and :func:`warehouse_from_mapping` build a
    :class:`taut.cdpr.Warehouse` (a mobile cable robot's floor, shelves, start and tasks).
Recordings (for robot viewers; metres and seconds)
    :func:`write_mcap` writes a result as a ROS 2 MCAP file (standard message types on the
    topics of :mod:`taut.io.mcap`, for Foxglove, RViz and ``ros2 bag play``; extra ``mcap``)
    and :func:`write_rerun` as a Rerun ``.rrd`` recording with a blueprint (extra
    ``rerun``): sheet FK, simulations, plans, MuJoCo checks, cable-robot simulations
    (docs/recordings.md).

Other file formats have their own modules: :mod:`taut.io.trajectory` (formation time
series, CSV), :mod:`taut.io.cdpr_reference` (platform reference poses, CSV),
:mod:`taut.io.cdpr_dynamics` (a model's dynamics section), :mod:`taut.io.caspr` (CASPR
models), and :mod:`taut.io.serialize` (the JSON forms of results, through
:func:`taut.io.serialize.json_ready`). Sweep files belong to :mod:`taut.sweep`.

The names above are imported on first use (PEP 562), so ``import taut.io.serialize`` (the
CLI's ``--help``) does not pull in scipy through the model loaders.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:                   # the real names, for type checkers
    from .cdpr_model import cdpr_model_from_mapping, load_cdpr_model
    from .files import (MAX_FILE_BYTES, MAX_YAML_CHARS, MAX_YAML_VALUES, parse_mapping,
                        read_mapping, read_text, validate_mapping, write_json, write_text_atomic,
                        atomic_path)
    from .plan_scenario import (load_plan_scenario, plan_scenario_from_mapping,
                                plan_scenario_to_mapping)
    from .sheet_scenario import SheetScenario, load_sheet_scenario, sheet_scenario_from_mapping
    from .warehouse import load_warehouse, warehouse_from_mapping
    from .mcap import write_mcap
    from .rerun import write_rerun

_HOME = {
    "cdpr_model_from_mapping": "cdpr_model", "load_cdpr_model": "cdpr_model",
    "read_mapping": "files", "read_text": "files", "validate_mapping": "files",
    "write_json": "files", "parse_mapping": "files", "write_text_atomic": "files",
    "atomic_path": "files",
    "MAX_FILE_BYTES": "files", "MAX_YAML_VALUES": "files", "MAX_YAML_CHARS": "files",
    "load_plan_scenario": "plan_scenario", "plan_scenario_from_mapping": "plan_scenario",
    "plan_scenario_to_mapping": "plan_scenario",
    "SheetScenario": "sheet_scenario", "load_sheet_scenario": "sheet_scenario",
    "sheet_scenario_from_mapping": "sheet_scenario",
    "load_warehouse": "warehouse", "warehouse_from_mapping": "warehouse",
    "write_mcap": "mcap", "write_rerun": "rerun",
}

__all__ = [
    # files
    "read_mapping", "read_text", "parse_mapping", "validate_mapping", "write_json",
    "write_text_atomic", "atomic_path", "MAX_FILE_BYTES", "MAX_YAML_VALUES",
    "MAX_YAML_CHARS",
    # sheet scenarios
    "load_sheet_scenario", "sheet_scenario_from_mapping", "SheetScenario",
    # plan scenarios
    "load_plan_scenario", "plan_scenario_from_mapping", "plan_scenario_to_mapping",
    # cable-robot models
    "load_cdpr_model", "cdpr_model_from_mapping",
    # warehouses
    "load_warehouse", "warehouse_from_mapping",
    # recordings
    "write_mcap", "write_rerun",
]


__getattr__, __dir__ = lazy_names(__name__, _HOME, globals())
