"""Warehouse files (YAML or JSON) of a mobile cable robot's mission (issue 30).

Top-level keys (unknown keys are errors; SI units: m, kg, rad, s):

``name`` (str), ``robot`` (a preset name such as ``fastkit``, or a model file path,
relative to the warehouse file), ``floor`` ([[x, y], ...] m, the free floor polygon),
``shelves`` (list of {``name``, ``footprint``: [[x, y], ...] m, optional ``height_m``:
the top above the floor, default 2.5 m}), ``start``
([x, y, yaw] m, m, rad: the coupled bases), ``tasks`` (list of {``name``, ``pick``:
[x, y, z] m, ``place``: [x, y, z] m, ``mass``: kg}), and the assumptions, each optional
with the default of :class:`taut.cdpr.Warehouse`: ``gripper_reach_m``, ``standoff_m``,
``clearance_m``, ``friction`` (or null), ``max_speed_m_s``, ``max_accel_m_s2``,
``max_turn_rate_rad_s``.

Every file goes through the safe loaders of :mod:`taut.io.files` (size limit, alias
bombs, duplicate keys, encodings); every error names the field (``tasks[2].pick``,
``shelves[0].footprint``, ``robot``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from pydantic import Field

from ..cdpr.mission.warehouse import SHELF_HEIGHT, Shelf, Task, Warehouse
from ..errors import ScenarioError, TautError
from .cdpr_model import load_cdpr_model
from .files import Number, StrictModel, read_mapping, validate_mapping
from .._validate import as_path

__all__ = ["load_warehouse", "warehouse_from_mapping"]

Vec3 = tuple[Number, Number, Number]
Vec2 = tuple[Number, Number]


class _Shelf(StrictModel):
    name: str = Field(min_length=1)
    footprint: list[Vec2] = Field(min_length=3)
    height_m: Number = SHELF_HEIGHT


class _Task(StrictModel):
    name: str = Field(min_length=1)
    pick: Vec3
    place: Vec3
    mass: Number


class _WarehouseFile(StrictModel):
    name: str = "warehouse"
    robot: str = Field(min_length=1)
    floor: list[Vec2] = Field(min_length=3)
    shelves: list[_Shelf] = []
    start: Vec3
    tasks: list[_Task] = Field(min_length=1)
    gripper_reach_m: Number = 1.0
    standoff_m: Number = 0.95
    clearance_m: Number = 0.1
    friction: Optional[Number] = 0.5
    max_speed_m_s: Number = 0.5
    max_accel_m_s2: Number = 0.25
    max_turn_rate_rad_s: Number = 0.2


#: File key of each Warehouse field whose name differs.
_KEYS = {"gripper_reach": "gripper_reach_m", "standoff": "standoff_m",
         "clearance": "clearance_m", "max_speed": "max_speed_m_s",
         "max_accel": "max_accel_m_s2", "max_turn_rate": "max_turn_rate_rad_s"}


def _robot(source: str, base_dir: str | Path | None) -> Any:
    p = Path(source)
    if base_dir is not None and not p.is_absolute() and (p.suffix or "/" in source):
        p = Path(base_dir) / p
    try:
        return load_cdpr_model(p if (p.suffix or "/" in source) else source)
    except TautError as exc:
        raise ScenarioError("robot", f"{exc.field}: {exc.problem}") from None


def warehouse_from_mapping(data: dict[str, Any], base_dir: str | Path | None = None
                           ) -> Warehouse:
    """Validate a parsed mapping and build the :class:`~taut.cdpr.Warehouse`.

    ``base_dir`` resolves a relative robot model path (default: the working directory).

    Raises
    ------
    ScenarioError
        Wrong types, unknown or missing keys, NaN/inf, a robot that does not load.
    InvalidInputError
        Inconsistent content (a shelf outside the floor or overlapping another, a task
        below the floor, a non-positive mass, two tasks with one name), field named as in
        the file.
    """
    raw = validate_mapping(_WarehouseFile, data)
    if base_dir is not None:
        base_dir = Path(as_path(base_dir, "base_dir"))
    robot = _robot(raw.robot, base_dir)
    try:
        shelves = []
        for k, s in enumerate(raw.shelves):
            shelves.append(_named(lambda s=s: Shelf(s.name, s.footprint, s.height_m),
                                  "shelves", k, s.name))
        tasks = []
        for k, t in enumerate(raw.tasks):
            tasks.append(_named(lambda t=t: Task(t.name, t.pick, t.place, t.mass), "tasks",
                                k, t.name))
        return Warehouse(robot=robot, floor=raw.floor, shelves=tuple(shelves),
                         start=raw.start, tasks=tuple(tasks),
                         gripper_reach=raw.gripper_reach_m, standoff=raw.standoff_m,
                         clearance=raw.clearance_m, max_speed=raw.max_speed_m_s,
                         max_accel=raw.max_accel_m_s2,
                         max_turn_rate=raw.max_turn_rate_rad_s, friction=raw.friction,
                         name=raw.name)
    except TautError as exc:
        f = exc.field
        raise type(exc)(_KEYS.get(f, f), exc.problem) from None


def _named(build: Any, kind: str, k: int, name: str) -> Any:
    """Build a shelf or task; its error names ``kind[k]`` as in the file."""
    try:
        return build()
    except TautError as exc:
        f = exc.field
        if f.startswith(f"{kind}[{name}]"):
            f = f"{kind}[{k}]" + f[len(f"{kind}[{name}]"):]
            f = f + "_m" if f.endswith(".height") else f
        elif f == f"{kind}.name":
            f = f"{kind}[{k}].name"
        raise type(exc)(f, exc.problem) from None


def load_warehouse(source: str | Path | dict[str, Any]) -> Warehouse:
    """Load a warehouse from a ``.yaml``/``.yml``/``.json`` file or a parsed mapping.

    Examples
    --------
    >>> wh = load_warehouse("examples/cdpr/warehouse.yaml")
    >>> wh.robot.name, len(wh.shelves), len(wh.tasks)
    ('fastkit', 3, 8)
    """
    if isinstance(source, dict):
        return warehouse_from_mapping(source)
    data = read_mapping(source)
    return warehouse_from_mapping(data, Path(str(source)).parent)
