"""Cable-robot model files (YAML or JSON) and the shipped presets.

Top-level keys (unknown keys are errors; SI units):

``name`` (str), ``gravity`` ([gx, gy, gz], m/s^2, default [0, 0, -9.81]),
``bases`` (list; each: ``name``, ``mobile`` (bool), ``pose`` [x, y, theta],
``exit_points`` {name: [x, y, z]} in the base frame, and for a mobile base ``mass``,
``com`` [x, y, z], ``footprint`` [[x, y], ...], optional ``stabilisers``
{``footprint``: [[x, y], ...], ``deployed``: bool}),
``platform`` (``mass``, ``com``, ``inertia`` (3 numbers or 3x3), ``attachment_points``
{name: [x, y, z]}), ``payload`` (``mass`` kg, ``com`` m, optional ``inertia`` kg m^2 about
its centre of mass, 3 numbers or 3x3, default a point mass), ``cables`` (list; each ``name``,
``exit`` "base.point", ``attachment``, ``t_min``, ``t_max``), optional ``bounds`` and
``desired_workspace`` ({``min``: [x, y, z], ``max``: [x, y, z]}), optional
``platform_inside_exits`` (bool, default false: the platform must stay inside the exits'
bounding box, a workspace condition), optional ``dynamics`` (elastic cables and winches;
keys and units in :mod:`taut.io.cdpr_dynamics`).

:func:`load_cdpr_model` accepts a preset name (``fastkit``, ``ipanema``) or a file path.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any, Optional, Union

from pydantic import Field

from .._units import GRAVITY
from ..cdpr.model.robot import Base, Cable, CableRobot, Payload, Platform
from ..errors import InvalidModelError, ScenarioError, TautError
from .files import Number, StrictModel, read_mapping, validate_mapping
from .._validate import MAX_CDPR_LENGTH_M, MAX_MASS_KG, as_path, check_range

__all__ = ["PRESETS", "load_cdpr_model", "cdpr_model_from_mapping", "preset_path"]

PRESETS = ("fastkit", "ipanema", "fastkit_fc")

Vec3 = tuple[Number, Number, Number]
Vec2 = tuple[Number, Number]


class _Stabilisers(StrictModel):
    footprint: list[Vec2]
    deployed: bool = False


class _Base(StrictModel):
    name: str
    mobile: bool = False
    pose: Vec3 = (0.0, 0.0, 0.0)
    mass: Number = 0.0
    com: Vec3 = (0.0, 0.0, 0.0)
    footprint: list[Vec2] | None = None
    stabilisers: _Stabilisers | None = None
    exit_points: dict[str, Vec3] = Field(min_length=1)
    friction: Number | None = None       # ground friction coefficient (sliding condition)


class _Platform(StrictModel):
    mass: Number = 0.0
    com: Vec3 = (0.0, 0.0, 0.0)
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3] = (0.0, 0.0, 0.0)
    attachment_points: dict[str, Vec3] = Field(min_length=1)


class _Payload(StrictModel):
    mass: Number = 0.0
    com: Vec3 = (0.0, 0.0, 0.0)
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3] = (0.0, 0.0, 0.0)


class _Cable(StrictModel):
    name: str
    exit: str
    attachment: str
    t_min: Number
    t_max: Number


class _Box(StrictModel):
    min: Vec3
    max: Vec3


class _Dynamics(StrictModel):
    """The ``dynamics:`` section (keys: :mod:`taut.io.cdpr_dynamics`; SI, motor side)."""
    # Defaults live in DynamicsModel only: a key left out keeps its default there; an
    # explicit null reaches DynamicsModel and is refused by its own checks.
    cable_stiffness: Optional[Number] = None
    cable_damping: Optional[Number] = None
    drum_diameter: Optional[Number] = None
    gear_ratio: Optional[Number] = None
    efficiency: Optional[Number] = None
    backdrive_efficiency: Optional[Number] = None
    rated_torque: Optional[Number] = None
    peak_torque: Optional[Number] = None
    peak_duration: Optional[Number] = None
    motor_speed_limit: Optional[Number] = None
    rotor_inertia: Optional[Number] = None
    friction_static: Optional[Number] = None
    friction_coulomb: Optional[Number] = None
    friction_viscous: Optional[Number] = None
    stribeck_speed: Optional[Number] = None
    drive_speed_gain: Optional[Number] = None
    drive_integral_gain: Optional[Number] = None
    routing_length: Optional[Union[Number, list[Number]]] = None


class _ModelFile(StrictModel):
    name: str = "cable robot"
    gravity: Vec3 = (0.0, 0.0, -GRAVITY)
    bases: list[_Base] = Field(min_length=1)
    platform: _Platform
    payload: _Payload = _Payload()
    cables: list[_Cable] = Field(min_length=1)
    bounds: _Box | None = None
    desired_workspace: _Box | None = None
    platform_inside_exits: bool = False
    # Elastic cables and winches: the section's keys are checked with the rest of the file
    # (an unknown key is ``dynamics.<key>: unknown key`` whatever the command); their
    # ranges are DynamicsModel's, when taut.io.cdpr_dynamics builds it.
    dynamics: _Dynamics | None = None


def _file_field(exc: TautError, raw: _ModelFile) -> str:
    """Turn a model field such as ``bases[active].footprint`` into ``bases[0].footprint``."""
    f = exc.field
    if f.startswith("bases[") and "]" in f:
        name, rest = f[6:].split("]", 1)
        for i, b in enumerate(raw.bases):
            if b.name == name:
                return f"bases[{i}]{rest}"
    return f


def cdpr_model_from_mapping(data: dict[str, Any]) -> CableRobot:
    """Validate a parsed mapping and build the :class:`CableRobot`.

    Raises
    ------
    ScenarioError
        Wrong types, unknown or missing keys, NaN/inf (field named by dotted path).
    InvalidModelError
        Inconsistent model: cable referencing a missing point, ``t_min > t_max``,
        non-convex or degenerate footprint, base centre of mass outside its footprint.
    """
    raw = validate_mapping(_ModelFile, data)
    try:
        bases = []
        for b in raw.bases:
            st = b.stabilisers
            bases.append(Base(name=b.name, exit_points=b.exit_points, pose=b.pose,
                              mobile=b.mobile, mass=b.mass, com=b.com,
                              footprint=b.footprint,
                              stabilisers=None if st is None else st.footprint,
                              stabilisers_deployed=bool(st is not None and st.deployed),
                              friction=b.friction))
        cables = []
        for i, c in enumerate(raw.cables):
            if c.exit.count(".") != 1:
                raise InvalidModelError(f"cables[{i}].exit",
                                        "must be 'base.point', e.g. 'active.A1'")
            base, point = c.exit.split(".")
            cables.append(Cable(c.name, base, point, c.attachment, c.t_min, c.t_max))
        p = raw.platform
        robot = CableRobot(
            bases=tuple(bases),
            platform=Platform(attachment_points=p.attachment_points, mass=p.mass, com=p.com,
                              inertia=p.inertia),
            cables=tuple(cables),
            payload=Payload(raw.payload.mass, raw.payload.com, raw.payload.inertia),
            gravity=raw.gravity,
            bounds=None if raw.bounds is None else (raw.bounds.min, raw.bounds.max),
            desired_workspace=(None if raw.desired_workspace is None else
                               (raw.desired_workspace.min, raw.desired_workspace.max)),
            name=raw.name, platform_inside_exits=raw.platform_inside_exits)
    except InvalidModelError as exc:
        raise InvalidModelError(_file_field(exc, raw), exc.problem) from None
    except TautError as exc:
        raise InvalidModelError(_file_field(exc, raw), exc.problem) from None
    return physical_ranges(robot)


def physical_ranges(robot: CableRobot) -> CableRobot:
    """``robot`` if its sizes are in the ranges every front end accepts
    (:mod:`taut._validate`): platform + payload mass at most ``MAX_MASS_KG`` kg, exit and
    attachment points and the frame box within ``MAX_CDPR_LENGTH_M`` m of the origin
    (tension limits are the model's own check, ``MAX_TENSION_N``). Every model loader
    applies it, so the CLI, the app and the library accept the same files.

    Raises
    ------
    InvalidModelError
        The field out of range, named as in a model file (``platform.mass``,
        ``payload.mass``, ``bases[0].exit_points.A1``, ``bases[0].pose``,
        ``platform.attachment_points.B1``, ``bounds``, ``desired_workspace``).
    """
    total = float(robot.platform.mass + robot.payload.mass)
    if not total <= MAX_MASS_KG:
        where = ("platform.mass" if not robot.platform.mass <= MAX_MASS_KG else
                 "payload.mass")
        raise InvalidModelError(where, f"platform + payload {total:g} kg exceeds "
                                f"the accepted range {MAX_MASS_KG:g} kg")
    r: Any = robot                         # exits_world: set when the model is validated
    checks: list[tuple[str, Any]] = []
    for i, b in enumerate(robot.bases):
        checks += [(f"bases[{i}].exit_points.{n}", p) for n, p in b.exit_points.items()]
        checks.append((f"bases[{i}].pose", b.pose[:2]))
    checks += [("bases", r.exits_world)]   # world exits: pose + point, each in range
    checks += [(f"platform.attachment_points.{n}", p)
               for n, p in robot.platform.attachment_points.items()]
    checks += [("bounds", robot.bounds), ("desired_workspace", robot.desired_workspace)]
    for where, values in checks:
        if values is not None:
            try:
                check_range(values, where, MAX_CDPR_LENGTH_M, "m")
            except TautError as exc:
                raise InvalidModelError(exc.field, exc.problem) from None
    return robot


def preset_path(name: str) -> Path:
    """Path of a shipped preset file; raises :class:`ScenarioError` for an unknown name."""
    if name not in PRESETS:
        raise ScenarioError("model", f"unknown preset {name!r}; presets: "
                                     + ", ".join(PRESETS) + " (or give a file path)")
    return Path(str(resources.files("taut") / "data" / f"{name}.yaml"))


def load_cdpr_model(source: str | Path) -> CableRobot:
    """Load a cable-robot model from a preset name or a ``.yaml``/``.yml``/``.json`` path.

    A bare word without a path separator or suffix is taken as a preset name.
    """
    as_path(source, "source")
    s = str(source)
    p = Path(s)
    if not p.exists() and p.suffix == "" and "/" not in s and "\\" not in s:
        p = preset_path(s)
    return cdpr_model_from_mapping(read_mapping(p))
