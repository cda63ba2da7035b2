"""ROS 2 recordings (MCAP) of taut's results, for Foxglove, RViz and ``ros2 bag play``.

:func:`write_mcap` writes a result as an MCAP file with the ``ros2`` profile: CDR-encoded
standard ROS 2 messages (definitions of ROS 2 Jazzy), metres and seconds, every header in
the frame ``world``, robots numbered from 1 like taut's tables.

=============================  ===================================  =======================
topic                          type                                 content
=============================  ===================================  =======================
``/taut/object/pose``          geometry_msgs/msg/PoseStamped        object (cable robot:
                                                                    platform) per sample
``/taut/robot_<i>/pose``       geometry_msgs/msg/PoseStamped        robot i (cable robot:
                                                                    mobile base i) on the
                                                                    ground
``/taut/robot_<i>/path``       nav_msgs/msg/Path                    robot i's planned path
                                                                    (plans; once, at t0)
``/taut/cables``               sensor_msgs/msg/JointState           per cable: length (m),
                                                                    rate (m/s), tension (N)
``/taut/platform/wrench``      geometry_msgs/msg/WrenchStamped      the cables' wrench on
                                                                    the platform (N, N m)
``/taut/markers``              visualization_msgs/msg/MarkerArray   sheet, cables,
                                                                    obstacles, walls
``/tf``                        tf2_msgs/msg/TFMessage               world -> object,
                                                                    world -> robot_<i>
=============================  ===================================  =======================

Each type's schema is its ``.msg`` definition as in ROS 2 Jazzy (fields and constants,
comments left out) followed by the definitions it depends on, each after a line of 80
``=`` and ``MSG: package/Type``, as rosbag2 stores them; messages are CDR-encoded by
``mcap-ros2-support`` from plain mappings. Message times are the result's times from 0 s (the MCAP epoch); sheet quantities are
converted to metres with ``length_unit`` (see :mod:`taut.io._recording`). Needs the extra
``mcap`` (``pip install 'taut[mcap]'``).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import as_path
from ._recording import Recording, recording_of, require_extra
from .files import atomic_path

__all__ = ["write_mcap", "TOPICS"]

#: Topic -> message type of every topic :func:`write_mcap` may write (``<i>``: 1-based).
TOPICS = {
    "/taut/object/pose": "geometry_msgs/msg/PoseStamped",
    "/taut/robot_<i>/pose": "geometry_msgs/msg/PoseStamped",
    "/taut/robot_<i>/path": "nav_msgs/msg/Path",
    "/taut/cables": "sensor_msgs/msg/JointState",
    "/taut/platform/wrench": "geometry_msgs/msg/WrenchStamped",
    "/taut/markers": "visualization_msgs/msg/MarkerArray",
    "/tf": "tf2_msgs/msg/TFMessage",
}

#: The fixed frame every message is expressed in.
FRAME = "world"

#: Marker type constants of visualization_msgs/msg/Marker used here.
_MARKER_TYPES = {"sphere_list": 7, "line_strip": 4, "line_list": 5, "triangle_list": 11}

_MSG: dict[str, str] = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "builtin_interfaces/Duration": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "std_msgs/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/Pose": "Point position\nQuaternion orientation",
    "geometry_msgs/PoseStamped": "std_msgs/Header header\nPose pose",
    "geometry_msgs/Wrench": "Vector3 force\nVector3 torque",
    "geometry_msgs/WrenchStamped": "std_msgs/Header header\nWrench wrench",
    "geometry_msgs/Transform": "Vector3 translation\nQuaternion rotation",
    "geometry_msgs/TransformStamped": ("std_msgs/Header header\nstring child_frame_id\n"
                                       "Transform transform"),
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "nav_msgs/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses",
    "sensor_msgs/JointState": ("std_msgs/Header header\nstring[] name\nfloat64[] position\n"
                               "float64[] velocity\nfloat64[] effort"),
    "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data",
    "visualization_msgs/UVCoordinate": "float32 u\nfloat32 v",
    "visualization_msgs/MeshFile": "string filename\nuint8[] data",
    "visualization_msgs/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n"
        "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n"
        "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
        "int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\n"
        "int32 DELETEALL=3\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
        "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\n"
        "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n"
        "string texture_resource\nsensor_msgs/CompressedImage texture\n"
        "UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n"
        "MeshFile mesh_file\nbool mesh_use_embedded_materials"),
    "visualization_msgs/MarkerArray": "Marker[] markers",
}

#: The full type name of every message taut writes (``package/msg/Type``).
_SCHEMAS = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/WrenchStamped",
           "nav_msgs/msg/Path", "sensor_msgs/msg/JointState", "tf2_msgs/msg/TFMessage",
           "visualization_msgs/msg/MarkerArray")


def _field_types(short: str) -> list[str]:
    """Complex types named by the fields of ``short`` (``package/Type``), fully qualified."""
    package = short.split("/")[0]
    out = []
    for line in _MSG[short].splitlines():
        kind = line.split()[0].removesuffix("[]")
        if "=" in line or ("/" not in kind and kind[0].islower()):   # constants, primitives
            continue
        out.append(kind if "/" in kind else f"{package}/{kind}")
    return out


def _schema_text(name: str) -> str:
    """The ``.msg`` definition of ``name`` (``package/msg/Type``) followed by every
    definition it depends on, each once, depth first.

    Examples
    --------
    >>> lines = _schema_text("geometry_msgs/msg/PoseStamped").splitlines()
    >>> lines[:2], lines[2] == "=" * 80, [x for x in lines if x.startswith("MSG:")]
    (['std_msgs/Header header', 'Pose pose'], True, ['MSG: std_msgs/Header', 'MSG: builtin_interfaces/Time', 'MSG: geometry_msgs/Pose', 'MSG: geometry_msgs/Point', 'MSG: geometry_msgs/Quaternion'])
    """
    short = name.replace("/msg/", "/")
    seen: list[str] = []
    stack = list(reversed(_field_types(short)))
    while stack:
        dep = stack.pop()
        if dep not in seen:
            seen.append(dep)
            stack.extend(reversed(_field_types(dep)))
    parts = [_MSG[short]] + [f"{'=' * 80}\nMSG: {dep}\n{_MSG[dep]}" for dep in seen]
    return "\n".join(parts) + "\n"


def _stamp(t: float) -> dict[str, int]:
    ns = int(round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _header(t: float) -> dict[str, Any]:
    """std_msgs/Header at ``t`` seconds in the ``world`` frame."""
    return {"stamp": _stamp(t), "frame_id": FRAME}


def _xyz(p: np.ndarray) -> dict[str, float]:
    return {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])}


def _pose(position: np.ndarray, quaternion: np.ndarray) -> dict[str, Any]:
    """geometry_msgs/Pose from a position (3,) m and a quaternion (x, y, z, w)."""
    q = quaternion
    return {"position": _xyz(position),
            "orientation": {"x": float(q[0]), "y": float(q[1]), "z": float(q[2]),
                            "w": float(q[3])}}


def _pose_stamped(t: float, position: np.ndarray, quaternion: np.ndarray) -> dict[str, Any]:
    """geometry_msgs/PoseStamped at ``t`` s."""
    return {"header": _header(t), "pose": _pose(position, quaternion)}


def _transform_stamped(t: float, child: str, position: np.ndarray, quaternion: np.ndarray
                      ) -> dict[str, Any]:
    """geometry_msgs/TransformStamped from ``world`` to ``child``."""
    p = _pose(position, quaternion)
    return {"header": _header(t), "child_frame_id": child,
            "transform": {"translation": p["position"], "rotation": p["orientation"]}}


def _marker(t: float, ns: str, kind: str, points: np.ndarray, rgba: tuple[float, ...],
           width: float, marker_id: int = 0) -> dict[str, Any]:
    """visualization_msgs/Marker of ``kind`` (a key of :data:`_MARKER_TYPES`) through
    ``points`` (K, 3) m in the world frame; ``width`` is the line width or sphere
    diameter, m."""
    r, g, b, a = rgba
    return {"header": _header(t), "ns": ns, "id": marker_id, "type": _MARKER_TYPES[kind],
            "action": 0, "pose": _pose(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])),
            "scale": {"x": width, "y": width, "z": width},
            "color": {"r": r, "g": g, "b": b, "a": a},
            "points": [_xyz(p) for p in points]}


_COLORS = {"sheet": (0.2, 0.5, 0.9, 0.35), "outline": (0.2, 0.4, 0.8, 1.0),
           "cables": (0.9, 0.5, 0.1, 1.0), "static": (0.4, 0.4, 0.4, 1.0),
           "points": (0.1, 0.7, 0.3, 1.0)}
#: Line width and point size of the markers, m.
_LINE_M = 0.005
_POINT_M = 0.02


def write_mcap(result: Any, path: str | os.PathLike[str], *, length_unit: Any = None,
               times: Any = None, team: Any = None, formation: Any = None,
               robot: Any = None, plan: Any = None) -> Path:
    """Write ``result`` as a ROS 2 MCAP recording (topics in the module docstring).

    Parameters
    ----------
    result
        :class:`taut.sheet.FKResult` (the lowest rest state at t = 0),
        :class:`taut.sheet.SimulationResult`, :class:`taut.plan.PlanResult`,
        :class:`taut.plan.RobotTrajectories` (each robot's heading),
        :class:`taut.physics.EquilibriaCheck` (one state a second),
        :class:`taut.physics.SettleResult` (with a trace),
        :class:`taut.cdpr.ControlResult` or :class:`taut.cdpr.MissionResult` (its track).
    path : path-like
        The ``.mcap`` file, replaced once complete.
    length_unit : str or float, optional
        The sheet scenario's unit (``"mm"``, ``"m"``, ...; or metres per unit): required for
        sheet results, which do not carry it.
    times : array_like, shape (T,), optional
        Time of each simulation step, s (SimulationResult: required).
    team : SheetTeam, optional
        The team of a physics result (required there).
    formation : array_like, shape (N, 2), optional
        The robots of a physics result, scenario units (required there).
    robot : CableRobot, optional
        The robot of a ControlResult (required there).
    plan : PlanResult, optional
        The plan a :class:`taut.plan.RobotTrajectories` executes (required there: the
        team and the obstacles).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InvalidInputError
        An unsupported result, a missing or unused context argument, or the ``mcap``
        extra not installed.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from taut.sheet import Sheet, SheetTeam, forward_kinematics
    >>> team = SheetTeam(Sheet.regular(4, 500.0), hold_height=800.0, mass=1.0)
    >>> fk = forward_kinematics(team, 0.8 * Sheet.regular(4, 500.0).vertices)
    >>> out = os.path.join(tempfile.mkdtemp(), "fk.mcap")
    >>> write_mcap(fk, out, length_unit="mm").suffix
    '.mcap'
    """
    writer_class = require_extra("mcap_ros2.writer", "mcap", "mcap").Writer
    rec = recording_of(result, length_unit=length_unit, times=times, team=team,
                       formation=formation, robot=robot, plan=plan)
    target = Path(as_path(path))
    with atomic_path(target) as tmp, open(tmp, "wb") as stream:
        writer = writer_class(stream)
        _write(writer, rec)
        writer.finish()
    return target


def _write(writer: Any, rec: Recording) -> None:
    schemas = {name: writer.register_msgdef(name, _schema_text(name))
               for name in _SCHEMAS}

    def put(topic: str, kind: str, t: float, message: Any) -> None:
        writer.write_message(topic, schemas[kind], message, log_time=int(round(t * 1e9)))

    n = rec.robot_xyz.shape[1]
    if rec.paths:
        for i in range(n):
            poses = [_pose_stamped(t, rec.robot_xyz[k, i], rec.robot_q[k, i])
                     for k, t in enumerate(rec.times)]
            put(f"/taut/robot_{i + 1}/path", "nav_msgs/msg/Path", rec.times[0],
                {"header": _header(rec.times[0]), "poses": poses})
    put("/taut/markers", "visualization_msgs/msg/MarkerArray", rec.times[0],
        {"markers": _static_markers(rec)})
    for k, t in enumerate(rec.times):
        t = float(t)
        _write_sample(put, rec, k, t)


def _write_sample(put: Any, rec: Recording, k: int, t: float) -> None:
    stamped, tf = "geometry_msgs/msg/PoseStamped", []
    if np.all(np.isfinite(rec.object_xyz[k])):
        put("/taut/object/pose", stamped, t,
            _pose_stamped(t, rec.object_xyz[k], rec.object_q[k]))
        tf.append(_transform_stamped(t, "object", rec.object_xyz[k], rec.object_q[k]))
    for i in range(rec.robot_xyz.shape[1]):
        put(f"/taut/robot_{i + 1}/pose", stamped, t,
            _pose_stamped(t, rec.robot_xyz[k, i], rec.robot_q[k, i]))
        tf.append(_transform_stamped(t, f"{rec.robot_label}_{i + 1}", rec.robot_xyz[k, i],
                                        rec.robot_q[k, i]))
    put("/tf", "tf2_msgs/msg/TFMessage", t, {"transforms": tf})
    put("/taut/cables", "sensor_msgs/msg/JointState", t,
        {"header": _header(t), "name": list(rec.cable_names),
         "position": rec.cable_length[k].tolist(), "velocity": rec.cable_speed[k].tolist(),
         "effort": [] if rec.cable_tension is None else rec.cable_tension[k].tolist()})
    if rec.wrench is not None:
        w = rec.wrench[k]
        put("/taut/platform/wrench", "geometry_msgs/msg/WrenchStamped", t,
            {"header": _header(t),
             "wrench": {"force": dict(zip("xyz", map(float, w[:3]))),
                        "torque": dict(zip("xyz", map(float, w[3:])))}})
    put("/taut/markers", "visualization_msgs/msg/MarkerArray", t,
        {"markers": _moving_markers(rec, k, t)})


def _static_markers(rec: Recording) -> list[dict[str, Any]]:
    t = float(rec.times[0])
    out = [_marker(t, name, "line_list", segs.reshape(-1, 3), _COLORS["static"], _LINE_M)
           for name, segs in rec.static_lines]
    out += [_marker(t, name, "sphere_list", pts, _COLORS["points"], _POINT_M)
            for name, pts in rec.points]
    return out


def _moving_markers(rec: Recording, k: int, t: float) -> list[dict[str, Any]]:
    ring = np.concatenate([rec.outline[k], rec.outline[k][:1]])
    ends = rec.cable_ends[k][rec.cable_taut[k]]
    out = [_marker(t, "outline", "line_strip", ring, _COLORS["outline"], _LINE_M),
           _marker(t, "cables", "line_list", ends.reshape(-1, 3), _COLORS["cables"],
                      _LINE_M)]
    if rec.surface is not None:
        nodes, triangles = rec.surface
        tri = nodes[k][triangles].reshape(-1, 3)
        if np.all(np.isfinite(tri)):
            out.append(_marker(t, "sheet", "triangle_list", tri, _COLORS["sheet"], 1.0))
    return [m for m in out if np.all(np.isfinite([[p["x"], p["y"], p["z"]]
                                                  for p in m["points"]] or [[0.0]]))]
