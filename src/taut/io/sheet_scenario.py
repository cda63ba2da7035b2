"""Scenario files for sheet-carrying teams (YAML or JSON).

Keys: ``hold_height`` (required, > 0), ``sheet`` (required, list of [x, y] vertices in robot
order), ``formation`` (list of [x, y] robot positions; required by ``taut fk``), and the
optional ``units`` (a label only), ``mass`` (the object's mass, kg, > 0), ``object``
(the object's shape: ``radius``, > 0, in ``units``; used by ``taut physics``) and ``name``.
Unknown keys, keys given
twice, booleans in place of numbers and values outside the accepted range
(:data:`taut._validate.MAX_SHEET_LENGTH`, :data:`taut._validate.MAX_MASS_KG`) are errors.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import Field

from .._validate import MAX_ROBOTS, MAX_SHEET_LENGTH, check_range
from ..errors import ScenarioError, TautError
from ..sheet.model import Sheet, check_formation
from ..sheet.team import SheetTeam
from .files import Number, StrictModel, read_mapping, validate_mapping
from .._repr import CompactRepr

__all__ = ["SheetScenario", "load_sheet_scenario", "sheet_scenario_from_mapping"]

Point = tuple[Number, Number]


class _ObjectFile(StrictModel):

    radius: Number = Field(gt=0)


class _SheetScenarioFile(StrictModel):

    name: str | None = None
    units: str | None = None
    hold_height: Number
    mass: Number | None = None
    sheet: list[Point]
    formation: list[Point] | None = None
    object: _ObjectFile | None = None


@dataclass(frozen=True, eq=False, repr=False)
class SheetScenario(CompactRepr):
    """A validated sheet scenario.

    Attributes
    ----------
    team : SheetTeam
        The sheet, the holding height :math:`z_r` (in ``units``) and the object mass (kg,
        or None).
    formation : ndarray, shape (N, 2), or None
        Robot positions, in ``units``.
    units : str or None
        Length unit label (not interpreted).
    name : str or None
    object_radius : float or None
        The object's radius, in ``units`` (the physics check's ball), or None.
    """

    team: SheetTeam
    formation: np.ndarray | None
    units: str | None
    name: str | None
    object_radius: float | None = None


def _rename(exc: TautError, field: str) -> ScenarioError:
    tail = exc.field.split("[", 1)[1] if "[" in exc.field else None
    return ScenarioError(f"{field}[{tail}" if tail else field, exc.problem)


def sheet_scenario_from_mapping(data: dict) -> SheetScenario:
    """Validate an already-parsed mapping (see module docstring for the keys)."""
    raw = validate_mapping(_SheetScenarioFile, data)
    try:
        for field, value, limit, unit in (
                ("sheet", raw.sheet, MAX_SHEET_LENGTH, "scenario units"),
                ("formation", raw.formation, MAX_SHEET_LENGTH, "scenario units"),
                ("object.radius", None if raw.object is None else raw.object.radius,
                 MAX_SHEET_LENGTH, "scenario units")):
            if value is not None:
                check_range(value, field, limit, unit)
    except TautError as exc:
        raise ScenarioError(exc.field, exc.problem) from None
    if len(raw.sheet) > MAX_ROBOTS:
        raise ScenarioError("sheet", f"{len(raw.sheet)} vertices exceeds the accepted "
                                     f"{MAX_ROBOTS} robots")
    try:
        sheet = Sheet(np.array(raw.sheet, dtype=float))
    except TautError as exc:
        raise _rename(exc, "sheet") from None
    try:
        team = SheetTeam(sheet, raw.hold_height, raw.mass)
    except TautError as exc:
        raise ScenarioError(exc.field, exc.problem) from None
    formation = None
    if raw.formation is not None:
        try:
            formation = check_formation(sheet, np.array(raw.formation, dtype=float))
        except TautError as exc:
            raise ScenarioError("formation", exc.problem) from None
    return SheetScenario(team, formation, raw.units, raw.name,
                         None if raw.object is None else raw.object.radius)


def load_sheet_scenario(path: str | Path) -> SheetScenario:
    """Read and validate a sheet scenario file.

    Raises
    ------
    ScenarioError
        Missing file, syntax error, unknown or missing keys, wrong types, an invalid
        sheet, non-positive hold height or mass, an infeasible formation.
    """
    return sheet_scenario_from_mapping(read_mapping(path))
