"""Scenario and model files: load, validate, save. Solvers never import this package."""

from .cdpr_model import cdpr_model_from_mapping, load_cdpr_model
from .files import read_mapping, read_text, validate_mapping, write_json
from .plan_scenario import (load_plan_scenario, plan_scenario_from_mapping,
                            plan_scenario_to_mapping)
from .sheet_scenario import SheetScenario, load_sheet_scenario, sheet_scenario_from_mapping

__all__ = ["read_mapping", "read_text", "validate_mapping", "write_json", "SheetScenario",
           "load_cdpr_model", "cdpr_model_from_mapping",
           "load_sheet_scenario", "sheet_scenario_from_mapping",
           "load_plan_scenario", "plan_scenario_from_mapping", "plan_scenario_to_mapping"]
