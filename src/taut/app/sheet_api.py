"""JSON endpoints of the sheet explorer: load a scenario, forward kinematics on every
drag, inverse kinematics for a clicked target, quasi-static simulation of a drag path,
and the scenario as a YAML file ``taut fk`` reads back.

Every function takes the decoded JSON body (a dict) and returns a JSON-ready dict; bad
input raises :class:`taut.errors.TautError`. All physics is the library's:
:func:`taut.sheet.forward_kinematics`, :func:`taut.sheet.inverse_kinematics`,
:func:`taut.sheet.sim.simulate`. Lengths are in the scenario's unit, masses kg, tensions N.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import yaml

from ..io.serialize import ik_to_dict, simulation_to_dict
from ..errors import InfeasibleFormationError, InvalidInputError
from ..io import SheetScenario, sheet_scenario_from_mapping
from ..io.serialize import equilibrium_to_dict
from ..sheet import Sheet, SheetTeam, forward_kinematics, inverse_kinematics
from ..sheet import simulate
from .catalog import Catalog, regular_team
from .payload import ModelCache, field, mapping_from_upload, numbers

__all__ = ["SheetAPI", "MAX_SIM_STEPS"]

#: Most steps of one simulation request (a drag path), which keeps it within its budget.
MAX_SIM_STEPS = 20000
#: Keys of a sheet scenario file, in the order they are written.
_KEYS = ("name", "units", "hold_height", "mass", "sheet", "formation")


def _points(a: np.ndarray) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in np.asarray(a, dtype=float)]


def _default_formation(sc: SheetScenario) -> np.ndarray:
    """A formation for a scenario that has none: inverse kinematics (all cables taut) for
    the object under the sheet's centroid at half the shortest cable's depth."""
    team = sc.team
    vo = team.sheet.vertices.mean(axis=0)
    depth = min(0.5 * float(np.linalg.norm(team.sheet.vertices - vo, axis=1).min()),
                0.5 * team.hold_height)
    ik = inverse_kinematics(team, (*vo, team.hold_height - depth))
    if not ik.success:
        raise InvalidInputError("formation", "missing, and no all-taut formation holds the "
                                f"object under the sheet's centroid ({ik.message})")
    return ik.formation


def scenario_mapping(sc: SheetScenario) -> dict[str, Any]:
    """The file mapping of a validated scenario (inverse of
    :func:`taut.io.sheet_scenario_from_mapping`); a missing formation is filled in."""
    formation = sc.formation if sc.formation is not None else _default_formation(sc)
    out = {"name": sc.name, "units": sc.units, "hold_height": float(sc.team.hold_height),
           "mass": sc.team.mass, "sheet": _points(sc.team.sheet.vertices),
           "formation": _points(formation)}
    return {k: out[k] for k in _KEYS if out[k] is not None}


def _sheet(vertices: Any) -> Sheet:
    return Sheet(numbers(vertices, "sheet", 2))


class SheetAPI:
    """The sheet explorer's endpoints (one instance per server: it caches sheets so the
    solver's per-sheet precomputation is reused from drag to drag)."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog
        self.sheets = ModelCache(_sheet)

    def load(self, body: dict[str, Any]) -> dict[str, Any]:
        """``{"example": name}``, ``{"text": ..., "filename": ...}`` (an upload),
        ``{"regular": n}`` or ``{"scenario": mapping}`` -> ``{"scenario": mapping}``,
        validated by the CLI's loader."""
        if "example" in body:
            data = self.catalog.mapping("sheet", field(body, "example", str))
        elif "text" in body:
            data = mapping_from_upload(field(body, "text", str),
                                       field(body, "filename", str, default="upload.yaml"))
        elif "regular" in body:
            data = regular_team(field(body, "regular", int))
        else:
            data = field(body, "scenario", dict)
        return {"scenario": scenario_mapping(sheet_scenario_from_mapping(data))}

    def _team(self, body: dict[str, Any]) -> SheetTeam:
        vertices = field(body, "sheet", list)
        numbers(vertices, "sheet", 2)             # checked before it becomes a cache key
        sheet = self.sheets.get(vertices)
        hold = field(body, "hold_height", (int, float))
        mass = field(body, "mass", (int, float), default=None)
        return SheetTeam(sheet, float(hold), None if mass is None else float(mass))

    def fk(self, body: dict[str, Any]) -> dict[str, Any]:
        """Every equilibrium of ``formation``; an infeasible formation is an answer
        (``feasible: false`` with the pair), not an error."""
        team = self._team(body)
        formation = numbers(field(body, "formation", list), "formation", 2)
        t0 = time.perf_counter()
        try:
            res = forward_kinematics(team, formation)
        except InfeasibleFormationError as exc:
            return {"feasible": False, "pair": list(exc.pair), "message": str(exc),
                    "server_ms": 1e3 * (time.perf_counter() - t0)}
        eqs = [dict(equilibrium_to_dict(e), height=e.height) for e in res.equilibria]
        low = res.lowest
        return {"feasible": True, "equilibria": eqs,
                "lowest": None if low is None else res.equilibria.index(low),
                "stable_count": len(res.stable),
                "server_ms": 1e3 * (time.perf_counter() - t0)}

    def ik(self, body: dict[str, Any]) -> dict[str, Any]:
        """Formation holding the object stably at ``target`` ([x, y, z]) with every cable
        taut, staying close to ``reference`` (the current formation) when given."""
        ref = field(body, "reference", list, default=None)
        res = inverse_kinematics(self._team(body),
                                 numbers(field(body, "target", list), "target", 1),
                                 reference=None if ref is None else numbers(ref, "reference", 2))
        return {"ik": ik_to_dict(res)}

    def simulate(self, body: dict[str, Any]) -> dict[str, Any]:
        """Quasi-static simulation along ``formations`` (T x N x 2, one row per step)."""
        team = self._team(body)
        formations = field(body, "formations", list)
        if len(formations) > MAX_SIM_STEPS:
            raise InvalidInputError("formations", f"at most {MAX_SIM_STEPS} steps")
        start = field(body, "start", list, default=None)
        res = simulate(team, numbers(formations, "formations", 3),
                       start=None if start is None else numbers(start, "start", 1))
        return {"simulation": simulation_to_dict(res, None)}

    def yaml(self, body: dict[str, Any]) -> dict[str, Any]:
        """The scenario (with the current formation and mass) as a YAML file ``taut fk``
        reads; validated first, so only loadable files are offered."""
        data = field(body, "scenario", dict)
        mapping = scenario_mapping(sheet_scenario_from_mapping(data))
        text = ("# sheet scenario saved by `taut app`; read it back with: taut fk FILE\n"
                + yaml.safe_dump(mapping, sort_keys=False, default_flow_style=None))
        return {"yaml": text, "filename": "sheet_scenario.yaml"}

