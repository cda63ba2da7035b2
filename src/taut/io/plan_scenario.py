"""Planning scenario files (YAML or JSON) for ``taut plan``.

Schema (lengths in m, times in s, angles in rad; unknown keys are errors)::

    name: paper corridor            # optional
    free_space: [[0, -1], [6, -1], [6, 1], [0, 1]]   # simple polygon, the walls
    obstacles:                      # optional list
      - {id: "1", center: [2, 0], radius: 0.1, height: 0.1}     # cylinder
      - {id: box, polygon: [[3, -.2], [3.3, -.2], [3.3, .1]], height: 0.4}
    start: [0.8, 0]                 # object projection (x, y)
    goal: [5.2, 0]
    team:
      sheet: [[x, y], ...]          # or: regular: {n: 3, circumradius: 0.577}
      hold_height: 0.5
      robot_radius: 0.15
      height_safety: 0.05           # object above obstacles beneath and the ground
      lateral_safety: 0.05          # robot footprint to walls and obstacles
      speed: 0.1                    # m/s
      rotation_speed: 0.3           # rad/s
      mass: 0.17                    # optional, kg
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field, model_validator

from ..errors import ScenarioError, TautError
from ..plan.world import MAX_TEAM_ROBOTS, Obstacle, Scenario, Team, World
from ..sheet import Sheet, SheetTeam
from .files import Integer, Number, StrictModel, read_mapping, validate_mapping
from .._validate import require_instance

__all__ = ["load_plan_scenario", "plan_scenario_from_mapping", "plan_scenario_to_mapping"]

Point = tuple[Number, Number]


class _Regular(StrictModel):
    n: Integer = Field(ge=3)
    circumradius: Number = Field(gt=0)
    phase: Number = 0.0


class _Team(StrictModel):
    sheet: list[Point] | None = None
    regular: _Regular | None = None
    hold_height: Number = Field(gt=0)
    robot_radius: Number = Field(gt=0)
    height_safety: Number = Field(ge=0)
    lateral_safety: Number = Field(ge=0)
    speed: Number = Field(gt=0)
    rotation_speed: Number = Field(gt=0)
    mass: Number | None = Field(default=None, gt=0)

    @model_validator(mode="after")
    def _one_sheet(self):
        if (self.sheet is None) == (self.regular is None):
            raise ValueError("give exactly one of 'sheet' and 'regular'")
        return self


class _Obstacle(StrictModel):
    id: Integer | str
    height: Number = Field(gt=0)
    center: Point | None = None
    radius: Number | None = Field(default=None, gt=0)
    polygon: list[Point] | None = None

    @model_validator(mode="after")
    def _one_shape(self):
        if (self.polygon is None) == (self.center is None):
            raise ValueError("give either center and radius or a polygon")
        if self.center is not None and self.radius is None:
            raise ValueError("a circular obstacle needs a radius")
        return self


class _PlanFile(StrictModel):
    name: str | None = None
    units: str | None = None
    free_space: list[Point]
    obstacles: list[_Obstacle] = []
    start: Point
    goal: Point
    team: _Team


def plan_scenario_from_mapping(data: dict) -> Scenario:
    """Validate a parsed mapping into a :class:`~taut.plan.world.Scenario`.

    Raises
    ------
    ScenarioError
        Unknown, missing or mistyped keys; non-positive sizes or speeds; invalid polygons
        or sheet (the field is the dotted path in the file).
    PlanningError
        Obstacles overlapping walls or each other; start or goal outside the free space or
        inside an obstacle.
    """
    raw = validate_mapping(_PlanFile, data)
    t = raw.team
    if t.regular is not None and t.regular.n > MAX_TEAM_ROBOTS:   # before allocating it
        raise ScenarioError("team.regular.n", f"a planning team has at most "
                            f"{MAX_TEAM_ROBOTS} robots, got {t.regular.n}")
    try:
        if t.sheet is not None:
            sheet = Sheet(np.array(t.sheet, dtype=float))
        else:
            reg = t.regular
            assert reg is not None                       # checked by _Team._one_sheet
            sheet = Sheet.regular(reg.n, reg.circumradius, phase=reg.phase)
    except TautError as exc:
        raise ScenarioError("team.sheet", exc.problem) from None
    if sheet.n > MAX_TEAM_ROBOTS:
        raise ScenarioError("team.sheet", f"a planning team has at most {MAX_TEAM_ROBOTS} "
                            f"robots, got {sheet.n}")
    try:
        carrier = SheetTeam(sheet, t.hold_height, t.mass)
    except TautError as exc:
        raise ScenarioError(f"team.{exc.field}", exc.problem) from None
    try:
        team = Team(carrier, t.robot_radius, t.height_safety, t.lateral_safety, t.speed,
                    t.rotation_speed)
    except TautError as exc:
        raise ScenarioError(f"team.{exc.field}", exc.problem) from None
    obstacles = []
    for k, o in enumerate(raw.obstacles):
        try:
            obstacles.append(Obstacle(
                str(o.id), o.height, radius=o.radius,
                center=None if o.center is None else np.asarray(o.center, dtype=float),
                polygon=None if o.polygon is None else np.asarray(o.polygon, dtype=float)))
        except TautError as exc:
            part = exc.field.rsplit(".", 1)[1] if "." in exc.field else ""
            raise ScenarioError(f"obstacles[{k}]" + (f".{part}" if part else ""),
                                exc.problem) from None
    try:
        world = World(np.array(raw.free_space, dtype=float), tuple(obstacles))
    except ScenarioError:
        raise
    except TautError as exc:
        if exc.field == "free_space":
            raise ScenarioError("free_space", exc.problem) from None
        raise
    return Scenario(world, team, np.array(raw.start), np.array(raw.goal), raw.name)


def load_plan_scenario(path: str | Path) -> Scenario:
    """Read and validate a planning scenario file (see the module docstring)."""
    return plan_scenario_from_mapping(read_mapping(path))


def plan_scenario_to_mapping(scenario: Scenario) -> dict:
    """The file mapping of a scenario (inverse of :func:`plan_scenario_from_mapping`)."""
    require_instance(scenario, Scenario, "scenario")
    team = scenario.team
    obstacles = []
    for o in scenario.world.obstacles:
        item: dict = {"id": o.id, "height": float(o.height)}
        if o.polygon is None:
            assert o.center is not None and o.radius is not None   # a cylinder
            item.update(center=[float(x) for x in o.center], radius=float(o.radius))
        else:
            item["polygon"] = [[float(x), float(y)] for x, y in o.polygon]
        obstacles.append(item)
    team_map: dict[str, Any] = {
        "sheet": [[float(x), float(y)] for x, y in team.sheet.vertices],
        "hold_height": team.hold_height, "robot_radius": team.robot_radius,
        "height_safety": team.height_safety, "lateral_safety": team.lateral_safety,
        "speed": team.speed, "rotation_speed": team.rotation_speed,
    }
    if team.mass is not None:
        team_map["mass"] = team.mass
    out: dict[str, Any] = {
        "name": scenario.name,
        "free_space": [[float(x), float(y)] for x, y in scenario.world.free_space],
        "obstacles": obstacles,
        "start": [float(x) for x in scenario.start],
        "goal": [float(x) for x in scenario.goal],
        "team": team_map,
    }
    if scenario.name is None:
        del out["name"]
    return out
