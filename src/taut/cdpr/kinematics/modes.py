"""Operating modes and joint velocity limits of mobile cable robots (FASTKIT §3.2,
eqs. 10-16).

``"task"``: cables and the bases named in ``moving`` move, every other base is fixed
(default ``moving``: the first mobile base, FASTKIT's active base, listed first in its model
file). ``moving=()`` is the "bases fixed" case of the paper's Fig. 13.
``"navigation"``: all bases are coupled to the ``driver`` base (default the first mobile
base) and the platform is fixed to them; no cable moves.

Units: base yaw rates rad/s, base and cable speeds m/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, Sequence

import numpy as np

from ..._validate import as_array
from ...errors import InvalidInputError
from ..model.robot import CableRobot
from ..._validate import as_choice, require_instance, require_instances

__all__ = ["MotionLimits", "fastkit_motion_limits", "MODES", "ModeName", "Mode",
           "resolve_mode", "TWIST_LABELS", "BASE_JOINTS", "joint_bounds"]

MODES = ("task", "navigation")
ModeName = Literal["task", "navigation"]
TWIST_LABELS = ("vx", "vy", "vz", "wx", "wy", "wz")
BASE_JOINTS = ("theta", "rho1", "rho2")


def _pair(lo: Any, hi: Any, fld: str, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    a = as_array(lo, f"{fld}_min")
    b = as_array(hi, f"{fld}_max")
    try:
        a = np.broadcast_to(a, shape).astype(float)
        b = np.broadcast_to(b, shape).astype(float)
    except ValueError:
        raise InvalidInputError(fld, f"limits must be a number or have shape {shape}") from None
    if np.any(a > b):
        k = int(np.argmax(a > b))
        raise InvalidInputError(fld, f"minimum {a.flat[k]:g} exceeds maximum {b.flat[k]:g}")
    return a, b


@dataclass(frozen=True)
class MotionLimits:
    """Joint velocity limits of a mobile CDPR (FASTKIT eqs. 10-16).

    Parameters
    ----------
    base_min, base_max : (3,)
        Limits of every moving base's RPP joint rates ``(theta_dot [rad/s], rho1_dot [m/s],
        rho2_dot [m/s])`` (yaw rate, forward and lateral speed in the base frame).
    cable_min, cable_max : float or (m,)
        Cable speed limits, m/s (negative = reeling in).

    Raises
    ------
    InvalidInputError
        NaN/inf, wrong shape, or a minimum above its maximum.
    """

    base_min: Any = (-0.2, -0.2, -0.2)
    base_max: Any = (0.2, 0.2, 0.2)
    cable_min: Any = -2.0
    cable_max: Any = 2.0

    def __post_init__(self) -> None:
        lo, hi = _pair(self.base_min, self.base_max, "limits.base", (3,))
        object.__setattr__(self, "base_min", lo)
        object.__setattr__(self, "base_max", hi)
        c_lo = as_array(self.cable_min, "limits.cable_min")
        c_hi = as_array(self.cable_max, "limits.cable_max")
        if c_lo.ndim > 1 or c_hi.ndim > 1:
            raise InvalidInputError("limits.cable", "must be a number or a vector (m,)")
        shape = np.broadcast_shapes(c_lo.shape, c_hi.shape) if (c_lo.ndim or c_hi.ndim) else ()
        lo, hi = _pair(c_lo, c_hi, "limits.cable", shape)
        object.__setattr__(self, "cable_min", lo)
        object.__setattr__(self, "cable_max", hi)

    def cable_bounds(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """Cable speed limits broadcast to ``(m,)``, m/s."""
        try:
            return (np.broadcast_to(self.cable_min, (m,)).copy(),
                    np.broadcast_to(self.cable_max, (m,)).copy())
        except ValueError:
            raise InvalidInputError("limits.cable", f"has {np.size(self.cable_min)} entries "
                                                    f"for a robot with {m} cables") from None


def fastkit_motion_limits() -> MotionLimits:
    """FASTKIT's joint velocity limits as printed in the paper: active base
    ``|theta_dot| <= 0.2 rad/s``, ``|rho1_dot|, |rho2_dot| <= 0.2 m/s`` (eqs. 10-12) and cable
    speeds ``|l_dot| <= 2 m/s`` (eq. 16, from the motor/winch table). The passive base is
    fixed in task mode (eqs. 13-15) through the mode, not through these limits. They are
    the defaults of :class:`MotionLimits`."""
    return MotionLimits()


@dataclass(frozen=True)
class Mode:
    """A resolved operating mode: ``kind`` ("task" or "navigation"), the indices of the bases
    whose joints move (``moving``; the driver alone in navigation mode) and their names."""

    kind: str
    moving: tuple[int, ...]
    names: tuple[str, ...]


def resolve_mode(robot: CableRobot, mode: ModeName = "task",
                 moving: Sequence[str] | None = None) -> Mode:
    """Check a mode against the model.

    Parameters
    ----------
    mode : {"task", "navigation"}
    moving : sequence of base names, optional
        Task mode: the bases that move (default: the first mobile base; ``()`` fixes all).
        Navigation mode: exactly one driver base (default the first mobile base).

    Raises
    ------
    InvalidInputError
        Unknown mode, a base name the model lacks, a fixed (non-mobile) base asked to move,
        or no mobile base to drive in navigation mode.
    """
    require_instance(robot, CableRobot, "robot")
    as_choice(mode, MODES, "mode")
    if moving is not None and not isinstance(moving, str):
        require_instances(moving, str, "moving")
    names = [b.name for b in robot.bases]
    mobile = [b.name for b in robot.bases if b.mobile]
    if moving is None:
        chosen: tuple[str, ...] = tuple(mobile[:1])
    elif isinstance(moving, str):
        chosen = (moving,)
    else:
        chosen = tuple(str(s) for s in moving)
    for s in chosen:
        if s not in names:
            raise InvalidInputError("mode.moving", f"no base named {s!r} in model "
                                    f"{robot.name!r} (bases: {', '.join(names)})")
        if not robot.bases[names.index(s)].mobile:
            raise InvalidInputError("mode.moving", f"base {s!r} is a fixed frame, it cannot "
                                                   "move")
    if len(set(chosen)) != len(chosen):
        raise InvalidInputError("mode.moving", "a base is named twice")
    if mode == "navigation" and len(chosen) != 1:
        raise InvalidInputError("mode.moving", "navigation mode needs exactly one driver "
                                               "(mobile) base")
    return Mode(mode, tuple(names.index(s) for s in chosen), chosen)


def joint_bounds(robot: CableRobot, limits: MotionLimits, md: Mode
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper joint-rate bounds in the column order of ``FirstOrderModel.B``."""
    require_instance(robot, CableRobot, "robot")
    require_instance(limits, MotionLimits, "limits")
    require_instance(md, Mode, "md")
    lo = [limits.base_min] * len(md.moving)
    hi = [limits.base_max] * len(md.moving)
    if md.kind == "task":
        c_lo, c_hi = limits.cable_bounds(robot.m)
        lo.append(c_lo)
        hi.append(c_hi)
    if not lo:
        return np.zeros(0), np.zeros(0)
    return np.concatenate(lo), np.concatenate(hi)
