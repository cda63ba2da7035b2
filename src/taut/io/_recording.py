"""What a recording shows, read from a result: the one place that dispatches on result type.

:func:`recording_of` turns a result of taut (sheet forward kinematics, quasi-static
simulation, a plan, a MuJoCo replay, a cable-robot control simulation) into a
:class:`Recording`: time stamps in seconds, positions in metres, orientations as
quaternions, cable lengths, speeds and tensions, the lines a viewer draws and the time
series a dashboard plots. :mod:`taut.io.mcap` and :mod:`taut.io.rerun` write a recording;
neither knows any result type.

Sheet results are in the scenario's length unit, which they do not carry: those need
``length_unit`` (``"mm"``, ``"m"``, ... or metres per unit as a number). Robots of a sheet
team stand on the ground (z = 0) and hold their corner at the hold height.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module
from types import ModuleType
from typing import Any, Callable

import numpy as np

from ..errors import InvalidInputError

__all__ = ["Recording", "Series", "recording_of", "metres_per_unit", "LENGTH_UNITS",
           "quaternion_from_rpy", "require_extra"]

#: Range of metres per unit a numeric ``length_unit`` may give (micrometres to kilometres).
UNIT_RANGE = (1e-6, 1e3)
#: Metres per length unit, for the ``units:`` labels of sheet scenarios.
LENGTH_UNITS = {"m": 1.0, "dm": 0.1, "cm": 0.01, "mm": 0.001, "km": 1000.0,
                "in": 0.0254, "ft": 0.3048}


@dataclass(frozen=True)
class Series:
    """One time series: ``values`` (T, k) in ``unit``, a label per column."""

    name: str
    unit: str
    values: np.ndarray
    labels: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class Recording:
    """A result as a viewer shows it (SI units, world frame, T samples).

    Attributes
    ----------
    kind : str
        What was recorded (``"sheet_fk"``, ``"sheet_simulation"``, ``"plan"``,
        ``"physics"``, ``"cdpr_simulation"``).
    times : ndarray, shape (T,)
        s.
    object_xyz, object_q : ndarray, shapes (T, 3), (T, 4)
        Object (or platform) position, m, and orientation quaternion (x, y, z, w); NaN rows
        where there is none (the object lost).
    robot_xyz, robot_q : ndarray, shapes (T, N, 3), (T, N, 4)
        Robots (or mobile bases): position, m, and orientation.
    paths : bool
        The robots' paths are a plan (recorded as nav_msgs/Path).
    cable_names : tuple of str
    cable_length, cable_speed : ndarray, shape (T, m)
        Straight cable length, m, and its rate, m/s.
    cable_tension : ndarray, shape (T, m), or None
        N (None when the result has no tensions).
    cable_ends : ndarray, shape (T, m, 2, 3)
        Each cable's two ends, m (anchor first).
    cable_taut : ndarray of bool, shape (T, m)
    wrench : ndarray, shape (T, 6), or None
        Force (N) and moment (N m, about the platform's reference point) of the cables on
        the platform.
    outline : ndarray, shape (T, K, 3)
        A closed polygon drawn each sample (the held corners of the sheet, the platform).
    surface : tuple (nodes (T, M, 3), triangles (F, 3)) or None
        A triangulated surface drawn each sample (the sheet).
    static_lines : tuple of (str, ndarray (L, 2, 3))
        Segments drawn once (obstacles, walls), by name.
    points : tuple of (str, ndarray (K, 3))
        Points drawn once (e.g. every equilibrium of FK), by name.
    series : tuple of Series
        Time series (heights, margins, tensions) for dashboards.
    """

    kind: str
    times: np.ndarray
    object_xyz: np.ndarray
    object_q: np.ndarray
    robot_xyz: np.ndarray
    robot_q: np.ndarray
    paths: bool
    cable_names: tuple[str, ...]
    cable_length: np.ndarray
    cable_speed: np.ndarray
    cable_tension: np.ndarray | None
    cable_ends: np.ndarray
    cable_taut: np.ndarray
    wrench: np.ndarray | None
    outline: np.ndarray
    surface: tuple[np.ndarray, np.ndarray] | None
    static_lines: tuple[tuple[str, np.ndarray], ...]
    points: tuple[tuple[str, np.ndarray], ...]
    series: tuple[Series, ...]
    robot_label: str = "robot"


def require_extra(module: str, extra: str, field: str) -> ModuleType:
    """Import ``module`` of the optional ``extra``; when it is missing, one error naming
    the extra (``field``: the argument or option that asked for it)."""
    try:
        return import_module(module)
    except ImportError:
        raise InvalidInputError(field, f"needs the {extra} extra: pip install "
                                       f"'taut[{extra}]'") from None


def metres_per_unit(length_unit: Any) -> float:
    """Metres per unit of ``length_unit``: a name of :data:`LENGTH_UNITS` or a positive
    number.

    Examples
    --------
    >>> metres_per_unit("mm"), metres_per_unit(0.5)
    (0.001, 0.5)
    """
    if isinstance(length_unit, str):
        key = length_unit.strip().lower()
        if key in LENGTH_UNITS:
            return LENGTH_UNITS[key]
        raise InvalidInputError("length_unit", f"unknown unit {length_unit!r}; use one of "
                                f"{', '.join(LENGTH_UNITS)} or metres per unit as a number")
    if isinstance(length_unit, (int, float, np.floating)) and not isinstance(length_unit, bool):
        if UNIT_RANGE[0] <= length_unit <= UNIT_RANGE[1]:
            return float(length_unit)
    raise InvalidInputError("length_unit", f"must be a unit name or a number of metres per "
                                           f"unit in [{UNIT_RANGE[0]:g}, {UNIT_RANGE[1]:g}], "
                                           f"got {length_unit!r}")


def quaternion_from_rpy(rpy: np.ndarray) -> np.ndarray:
    """Quaternions (..., 4) as (x, y, z, w) of ``Rz(yaw) Ry(pitch) Rx(roll)``, the
    convention of :func:`taut.cdpr.rotation_matrices` and of ROS; ``rpy`` (..., 3), rad."""
    half = 0.5 * np.asarray(rpy, dtype=float)
    cr, cp, cy = np.cos(half[..., 0]), np.cos(half[..., 1]), np.cos(half[..., 2])
    sr, sp, sy = np.sin(half[..., 0]), np.sin(half[..., 1]), np.sin(half[..., 2])
    return np.stack([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy], axis=-1)


def _yaw_q(yaw: np.ndarray) -> np.ndarray:
    yaw = np.asarray(yaw, dtype=float)
    return quaternion_from_rpy(np.stack([np.zeros_like(yaw), np.zeros_like(yaw), yaw], -1))


def _rates(values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Time derivative along axis 0 (zeros for a single sample)."""
    if len(times) < 2:
        return np.zeros_like(values)
    return np.gradient(values, times, axis=0)


def _need(context: dict[str, Any], key: str, kind: str) -> Any:
    value = context.get(key)
    if value is None:
        raise InvalidInputError(key, f"is required to record a {kind}")
    return value


# --- sheet-carrying teams -------------------------------------------------------------

def _sheet_motion(kind: str, times: np.ndarray, formations: np.ndarray, obj: np.ndarray,
                  taut: np.ndarray, tensions: np.ndarray | None, hold: float,
                  yaw: np.ndarray, scale: float, series: list[Series],
                  **extra: Any) -> Recording:
    """A sheet team's recording from arrays in scenario units (scaled to metres by
    ``scale``): formations (T, N, 2), object (T, 3), taut mask (T, N), yaw (T,) of the
    team (the object turns with it) or (T, N) of each robot (the object is not turned)."""
    T, N = formations.shape[:2]
    yaw = np.asarray(yaw, dtype=float)
    xy = formations * scale
    robots = np.concatenate([xy, np.zeros((T, N, 1))], axis=2)
    corners = robots + np.array([0.0, 0.0, hold * scale])
    o = obj * scale
    length = np.linalg.norm(corners - o[:, None, :], axis=2)
    ends = np.stack([corners, np.broadcast_to(o[:, None, :], corners.shape)], axis=2)
    names = tuple(f"cable_{i + 1}" for i in range(N))
    series = [Series("object height", "m", o[:, 2:3], ("z",))] + series
    if tensions is not None:
        series.append(Series("cable tensions", "N", tensions, names))
    fan = (np.concatenate([corners, o[:, None, :]], axis=1),
           np.array([[i, (i + 1) % N, N] for i in range(N)], dtype=np.intp))
    if yaw.ndim == 1:
        object_q, robot_q = _yaw_q(yaw), np.repeat(_yaw_q(yaw)[:, None, :], N, axis=1)
    else:
        object_q, robot_q = _yaw_q(np.zeros(T)), _yaw_q(yaw)
    return Recording(kind, times, o, object_q, robots, robot_q,
                     extra.pop("paths", False), names, length, _rates(length, times),
                     tensions, ends, taut, None, corners,
                     extra.pop("surface", fan), extra.pop("static_lines", ()),
                     extra.pop("points", ()), tuple(series))


def _taut_mask(sets: Any, n: int) -> np.ndarray:
    mask = np.zeros((len(sets), n), dtype=bool)
    for k, s in enumerate(sets):
        mask[k, list(s)] = True
    return mask


def _from_fk(result: Any, context: dict[str, Any]) -> Recording:
    """The lowest rest state at t = 0 (every equilibrium drawn as points)."""
    scale = metres_per_unit(_need(context, "length_unit", "sheet FK result"))
    n = result.sheet.n
    e = result.lowest
    obj = np.full((1, 3), np.nan) if e is None else e.object[None].astype(float)
    taut = _taut_mask([() if e is None else e.taut], n)
    tensions = None
    if e is not None and e.tensions is not None:
        tensions = np.zeros((1, n))
        tensions[0, list(e.taut)] = e.tensions
    pts = tuple((f"equilibria/{kind}", np.array([q.object * scale for q in result.equilibria
                                                  if q.kind == kind]).reshape(-1, 3))
                for kind in ("stable", "saddle", "not_equilibrium"))
    return _sheet_motion("sheet_fk", np.zeros(1), result.formation[None], obj, taut,
                         tensions, result.hold_height, np.zeros(1), scale, [],
                         points=tuple(p for p in pts if len(p[1])))


def _from_simulation(result: Any, context: dict[str, Any]) -> Recording:
    kind = "sheet simulation"
    scale = metres_per_unit(_need(context, "length_unit", kind))
    times = np.asarray(_need(context, "times", kind), dtype=float)
    if times.shape != (len(result),):
        raise InvalidInputError("times", f"must have shape ({len(result)},): one time (s) "
                                         "per simulation step")
    n = result.formations.shape[1]
    return _sheet_motion("sheet_simulation", times, result.formations, result.object,
                         _taut_mask(result.taut, n), result.tensions, result.hold_height,
                         np.zeros(len(times)), scale, [])


def _obstacle_lines(scenario: Any) -> tuple[tuple[str, np.ndarray], ...]:
    """Edges of every obstacle's prism and the walls, (L, 2, 3) m."""
    out = []
    for ob in scenario.world.obstacles:
        ring = np.asarray(ob.geometry.exterior.coords)[:-1]
        lo = np.column_stack([ring, np.zeros(len(ring))])
        hi = lo + [0.0, 0.0, ob.height]
        nxt = np.roll(np.arange(len(ring)), -1)
        segs = np.concatenate([np.stack([lo, lo[nxt]], 1), np.stack([hi, hi[nxt]], 1),
                               np.stack([lo, hi], 1)[:: max(1, len(ring) // 8)]])
        out.append((f"obstacles/{ob.id}", segs))
    walls = np.asarray(scenario.world.free_space, dtype=float)
    w3 = np.column_stack([walls, np.zeros(len(walls))])
    out.append(("walls", np.stack([w3, np.roll(w3, -1, axis=0)], 1)))
    return tuple(out)


def _plan_series(scenario: Any, robots: np.ndarray, obj: np.ndarray) -> list[Series]:
    """Margins of a sheet team's motion (m): the object above the tallest obstacle
    beneath the sheet (NaN where none) and the least sheet slack over robot pairs."""
    from ..plan.checks._geometry import beneath_height, pair_slack
    beneath = beneath_height(scenario, robots)
    over = np.where(beneath > 0, obj[:, 2] - beneath, np.nan)
    slack = pair_slack(scenario, robots)[0].min(axis=1)
    return [Series("margins", "m", np.column_stack([over, slack]),
                   ("object above obstacle", "sheet slack"))]


def _from_plan(result: Any, context: dict[str, Any]) -> Recording:
    if not result.success or len(result.times) == 0:
        raise InvalidInputError("result", f"the plan has no motion to record ({result.status}: "
                                          f"{result.message})")
    team = result.scenario.team
    n = result.robots.shape[1]
    return _sheet_motion("plan", result.times, result.robots, result.object,
                         _taut_mask(result.taut, n), None, team.hold_height, result.heading,
                         1.0, _plan_series(result.scenario, result.robots, result.object),
                         paths=True, static_lines=_obstacle_lines(result.scenario))


def _from_trajectories(result: Any, context: dict[str, Any]) -> Recording:
    """Per-robot trajectories of a plan (``plan``: the PlanResult they execute, for the
    team and the obstacles); every cable drawn (the trajectories carry no taut sets)."""
    plan = _need(context, "plan", "robot trajectories")
    if not result.success or len(result.times) == 0:
        raise InvalidInputError("result", f"the trajectories hold no motion to record "
                                          f"({result.status}: {result.message})")
    T, N = result.poses.shape[:2]
    return _sheet_motion("plan", result.times, result.poses[..., :2], result.object,
                         np.ones((T, N), bool), None, plan.scenario.team.hold_height,
                         result.poses[..., 2], 1.0,
                         _plan_series(plan.scenario, result.poses[..., :2], result.object),
                         paths=True,
                         static_lines=_obstacle_lines(plan.scenario))


def _from_equilibria_check(result: Any, context: dict[str, Any]) -> Recording:
    """One sample per checked state, 1 s apart: where MuJoCo's released object rests,
    on the tied, settled sheet mesh; taut's prediction drawn as points."""
    kind = "physics check"
    scale = metres_per_unit(_need(context, "length_unit", kind))
    team = _need(context, "team", kind)
    formation = np.asarray(_need(context, "formation", kind), dtype=float)
    S = len(result.states)
    if S == 0:
        raise InvalidInputError("result", "the check holds no state to record")
    settled = np.array([s.settled for s in result.states], dtype=float)
    taut = _taut_mask([s.taut for s in result.states], team.n)
    meshes = {s.nodes.shape for s in result.states}
    surface = None
    if len(meshes) == 1:
        surface = (np.array([s.nodes for s in result.states]) * scale,
                   np.asarray(result.states[0].triangles, dtype=np.intp))
    pred = np.array([s.predicted for s in result.states], dtype=float)
    return _sheet_motion("physics", np.arange(S, dtype=float),
                         np.broadcast_to(formation, (S,) + formation.shape), settled, taut,
                         None, team.hold_height, np.zeros(S), scale,
                         [Series("settled minus predicted", "m",
                                 (settled - pred) * scale, ("dx", "dy", "dz"))],
                         surface=surface, points=(("predicted", pred * scale),))


def _from_settle(result: Any, context: dict[str, Any]) -> Recording:
    """The dropped ball's trace (needs ``settle(..., trace=True)``)."""
    kind = "settle result"
    scale = metres_per_unit(_need(context, "length_unit", kind))
    team = _need(context, "team", kind)
    formation = np.asarray(_need(context, "formation", kind), dtype=float)
    if result.trace is None:
        raise InvalidInputError("result", "has no trace: run settle(..., trace=True)")
    times = result.trace[:, 0]
    T = len(times)
    surface = None
    if result.frames is not None:
        surface = (result.frames * scale, np.asarray(result.triangles, dtype=np.intp))
    return _sheet_motion("physics", times, np.broadcast_to(formation, (T,) + formation.shape),
                         result.trace[:, 1:4], np.zeros((T, team.n), bool), None,
                         team.hold_height, np.zeros(T), scale, [], surface=surface)


# --- cable robots ---------------------------------------------------------------------

def _from_control(result: Any, context: dict[str, Any]) -> Recording:
    from ..cdpr.kinematics._bases import moved_exits, moved_edges
    from ..cdpr.kinematics.cables import rotation_matrices

    robot = _need(context, "robot", "cable-robot simulation")
    times = result.times
    T = len(times)
    P = result.poses[:, :3]
    R = rotation_matrices(result.poses[:, 3:])
    attach = P[:, None, :] + np.einsum("tij,mj->tmi", R, robot.attach_local)
    exits = moved_exits(robot, result.base_poses)
    vec = exits - attach
    length = np.linalg.norm(vec, axis=2)
    force = result.tensions[:, :, None] * vec / length[:, :, None]
    moment = np.cross(attach - P[:, None, :], force)
    wrench = np.concatenate([force.sum(1), moment.sum(1)], axis=1)
    bp = result.base_poses
    bases = np.concatenate([bp[..., :2], np.zeros(bp.shape[:2] + (1,))], axis=2)
    lines = []
    if robot.n_edges:
        pts = moved_edges(robot, bp[:1])[0][0]
        nxt = np.array([e + 1 if e + 1 < robot.n_edges and robot.edge_base[e + 1] == b
                        else int(np.flatnonzero(robot.edge_base == b)[0])
                        for e, b in enumerate(robot.edge_base)])
        lines.append(("bases/support", np.stack([pts, pts[nxt]], axis=1)))
    names = tuple(result.cable_names)
    series = [Series("platform height", "m", P[:, 2:3], ("z",)),
              Series("tracking error", "m", result.tracking_error[:, None], ("error",)),
              Series("cable tensions", "N", result.tensions, names)]
    if result.tipping_margin.shape[1]:
        series.append(Series("tipping margins", "N m", result.tipping_margin,
                             tuple(result.edge_names)))
    return Recording("cdpr_simulation", times, P, quaternion_from_rpy(result.poses[:, 3:]),
                     bases, _yaw_q(bp[..., 2]), False, names, length, _rates(length, times),
                     result.tensions, np.stack([exits, attach], axis=2),
                     np.ones((T, robot.m), bool), wrench, attach, None, tuple(lines), (),
                     tuple(series), robot_label="base")


def _from_mission(result: Any, context: dict[str, Any]) -> Recording:
    """The cable robot's mission track: the platform as the object, the coupled bases as
    one robot (x, y, yaw); the mission records no cables, so none are drawn."""
    times = np.asarray(result.track_times, dtype=float)
    T = len(times)
    if T == 0:
        raise InvalidInputError("result", f"the mission has no track to record "
                                          f"({result.status}: {result.message})")
    P = np.asarray(result.track_platform, dtype=float)
    bases = np.asarray(result.track_bases, dtype=float)
    robot = np.column_stack([bases[:, :2], np.zeros(T)])[:, None, :]
    return Recording("cdpr_mission", times, P, _yaw_q(np.zeros(T)), robot,
                     _yaw_q(bases[:, 2])[:, None, :], True, (), np.zeros((T, 0)),
                     np.zeros((T, 0)), None, np.zeros((T, 0, 2, 3)), np.zeros((T, 0), bool),
                     None, P[:, None, :], None, (), (),
                     (Series("platform height", "m", P[:, 2:3], ("z",)),),
                     robot_label="base")


#: Result type (module, class name) -> converter. The names are read, not imported, so
#: recording a plan loads no physics and recording a sheet loads no cable robot. A new
#: result type (the plan's per-robot trajectories, the cable robot's mission) is one line.
_CONVERTERS: dict[tuple[str, str], Callable[[Any, dict[str, Any]], Recording]] = {
    ("taut.sheet.fk.results", "FKResult"): _from_fk,
    ("taut.sheet.sim.results", "SimulationResult"): _from_simulation,
    ("taut.plan.result", "PlanResult"): _from_plan,
    ("taut.plan.execution.trajectories", "RobotTrajectories"): _from_trajectories,
    ("taut.physics.sheet", "EquilibriaCheck"): _from_equilibria_check,
    ("taut.physics.sheet", "SettleResult"): _from_settle,
    ("taut.cdpr.control.results", "ControlResult"): _from_control,
    ("taut.cdpr.mission.mission", "MissionResult"): _from_mission,
}

#: Context each converter reads (anything else given is an error).
_CONTEXT: dict[Callable[[Any, dict[str, Any]], Recording], set[str]] = {_from_fk: {"length_unit"}, _from_simulation: {"length_unit", "times"},
            _from_plan: set(), _from_trajectories: {"plan"},
            _from_equilibria_check: {"length_unit", "team", "formation"},
            _from_settle: {"length_unit", "team", "formation"}, _from_control: {"robot"},
            _from_mission: set()}


def recording_of(result: Any, **context: Any) -> Recording:
    """The :class:`Recording` of ``result``; ``context`` holds what the result does not
    carry (``length_unit``, ``times``, ``team``, ``formation``, ``robot``, ``plan``).

    Raises
    ------
    InvalidInputError
        ``result`` is of a type taut does not record, a needed context entry is missing
        or one is given that the type does not use.
    """
    key = (type(result).__module__, type(result).__name__)
    convert = _CONVERTERS.get(key)
    if convert is None:
        known = ", ".join(name for _, name in _CONVERTERS)
        raise InvalidInputError("result", f"cannot record a {type(result).__name__}; "
                                          f"recorded results: {known}")
    given = {k for k, v in context.items() if v is not None}
    extra = given - _CONTEXT.get(convert, set())
    if extra:
        name = sorted(extra)[0]
        raise InvalidInputError(name, f"does not apply to a {type(result).__name__}")
    return convert(result, context)
