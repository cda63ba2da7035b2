"""Scenario and model files: load, validate, save. Solvers never import this package."""

from .files import read_mapping, validate_mapping, write_json
from .sheet_scenario import SheetScenario, load_sheet_scenario, sheet_scenario_from_mapping

__all__ = ["read_mapping", "validate_mapping", "write_json", "SheetScenario",
           "load_sheet_scenario", "sheet_scenario_from_mapping"]
