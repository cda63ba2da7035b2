"""Scenario and model files: load, validate, save. Solvers never import this package.

The names below are imported on first use (PEP 562), so ``import taut.io.serialize`` (the
CLI's ``--help``) does not pull in scipy through the model loaders.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                   # the real names, for type checkers
    from .cdpr_model import cdpr_model_from_mapping, load_cdpr_model
    from .files import read_mapping, read_text, validate_mapping, write_json
    from .plan_scenario import (load_plan_scenario, plan_scenario_from_mapping,
                                plan_scenario_to_mapping)
    from .sheet_scenario import SheetScenario, load_sheet_scenario, sheet_scenario_from_mapping

_HOME = {
    "cdpr_model_from_mapping": "cdpr_model", "load_cdpr_model": "cdpr_model",
    "read_mapping": "files", "read_text": "files", "validate_mapping": "files",
    "write_json": "files",
    "load_plan_scenario": "plan_scenario", "plan_scenario_from_mapping": "plan_scenario",
    "plan_scenario_to_mapping": "plan_scenario",
    "SheetScenario": "sheet_scenario", "load_sheet_scenario": "sheet_scenario",
    "sheet_scenario_from_mapping": "sheet_scenario",
}

__all__ = ["read_mapping", "read_text", "validate_mapping", "write_json", "SheetScenario",
           "load_cdpr_model", "cdpr_model_from_mapping",
           "load_sheet_scenario", "sheet_scenario_from_mapping",
           "load_plan_scenario", "plan_scenario_from_mapping", "plan_scenario_to_mapping"]


def __getattr__(name: str) -> Any:
    if name in _HOME:
        value = getattr(import_module(f"{__name__}.{_HOME[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
