"""Scenario and model files: load, validate, save. Solvers never import this package."""

from .files import read_mapping, validate_mapping, write_json

__all__ = ["read_mapping", "validate_mapping", "write_json"]
