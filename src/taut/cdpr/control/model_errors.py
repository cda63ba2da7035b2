"""Model errors between the nominal model a controller uses and the plant it drives (FASTKIT
paper §2.2: "because of ineluctable model errors, cables might get slack or too stretched").

The controller always uses the nominal robot and :class:`DynamicsModel`; the simulated plant
uses the perturbed one drawn here: the robot as it is, against the model the controller holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._validate import as_bounded, as_finite_scalar
from ...errors import InvalidInputError
from ..model.robot import CableRobot

__all__ = ["ModelErrors"]


@dataclass(frozen=True)
class PlantPerturbation:
    """Drawn errors of one plant.

    Attributes
    ----------
    exit_offsets : (m, 3)
        Added to every cable's world exit point, m.
    length_offsets : (m,)
        Encoder (zero-length) error per cable: the controller reads ``L0 + offset``, m.
    friction_scale, mass_scale : float
        Plant friction and moving mass (platform + payload) relative to nominal.
    efficiency_scales, friction_scales, inertia_scales : (m,)
        Per-winch relative efficiency (forward and back-drive, capped at 1), friction and
        rotor inertia of the plant (1 = nominal); ``friction_scales`` multiplies
        ``friction_scale``.
    payload_scale : float
        Plant payload mass relative to nominal (moves the centre of mass too).
    """

    exit_offsets: np.ndarray
    length_offsets: np.ndarray
    friction_scale: float
    mass_scale: float
    efficiency_scales: np.ndarray
    friction_scales: np.ndarray
    inertia_scales: np.ndarray
    payload_scale: float = 1.0


@dataclass(frozen=True)
class ModelErrors:
    """Seeded model errors of a simulated plant.

    Parameters
    ----------
    exit_offset : float
        Standard deviation of the normal error of each coordinate of each exit point, m.
    length_offset : float
        Standard deviation of the normal encoder error of each cable length, m.
    friction_scale : float
        Plant motor friction = ``friction_scale`` x the controller's estimate (> 0).
    mass_scale : float
        Plant platform + payload mass (and inertia) = ``mass_scale`` x nominal (> 0).
    base_pose : (float, float)
        ``(sigma_xy, sigma_yaw)``: standard deviations (m, rad) of the placement error of each
        mobile base; a base's exits move together with its pose (rotation about the base
        origin), the errors of different bases are independent. Default no error.
    winch : float
        Relative standard deviation (dimensionless) of each winch's efficiency, friction and
        rotor inertia, drawn independently per winch and quantity (plant = nominal x
        ``1 + winch N(0, 1)``, clipped to [0.1, 10]; efficiencies capped at 1).
    payload_mass : float
        Relative standard deviation (dimensionless) of the payload mass: plant payload =
        nominal x ``1 + payload_mass N(0, 1)`` (clipped to [0.1, 10]); the centre of mass and
        inertia follow.
    seed : int
        Seed of the normal draws (``numpy.random.default_rng``).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> e = ModelErrors(exit_offset=0.005, seed=3).draw(load_cdpr_model("fastkit"))
    >>> e.exit_offsets.shape, float(e.friction_scale)
    ((8, 3), 1.0)
    """

    exit_offset: float = 0.0
    length_offset: float = 0.0
    friction_scale: float = 1.0
    mass_scale: float = 1.0
    base_pose: Any = (0.0, 0.0)
    winch: float = 0.0
    payload_mass: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("exit_offset", "length_offset"):
            v = as_bounded(getattr(self, name), f"model_errors.{name}", 1.0, "m "
                           "(a standard deviation; 1 m is already larger than FASTKIT)",
                           positive=False)
            object.__setattr__(self, name, v)
        for name in ("friction_scale", "mass_scale"):
            v = as_finite_scalar(getattr(self, name), f"model_errors.{name}")
            if not v > 0:
                raise InvalidInputError(f"model_errors.{name}", f"must be positive, got {v:g}")
            object.__setattr__(self, name, v)
        try:
            bp = np.asarray(self.base_pose, dtype=float) \
                if not isinstance(self.base_pose, (str, bytes)) else np.array([np.nan])
        except (TypeError, ValueError):
            bp = np.array([np.nan])
        if bp.shape != (2,) or not np.all(np.isfinite(bp)) or np.any(bp < 0) \
                or bp[0] > 1.0 or bp[1] > np.pi:
            raise InvalidInputError("model_errors.base_pose", "must be (sigma_xy, sigma_yaw): "
                                    "two non-negative standard deviations, m (<= 1) and rad "
                                    f"(<= pi), got {self.base_pose!r}")
        object.__setattr__(self, "base_pose", (float(bp[0]), float(bp[1])))
        w = as_bounded(self.winch, "model_errors.winch", 1.0, "(a relative standard "
                       "deviation, dimensionless)", positive=False)
        object.__setattr__(self, "winch", w)
        object.__setattr__(self, "payload_mass", as_bounded(
            self.payload_mass, "model_errors.payload_mass", 1.0, "(a relative standard "
            "deviation, dimensionless)", positive=False))
        s = self.seed
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 0:
            raise InvalidInputError("model_errors.seed", f"must be a non-negative integer, "
                                                         f"got {s!r}")

    def draw(self, robot: CableRobot) -> PlantPerturbation:
        """Draw this plant's errors for ``robot`` (deterministic in ``seed``)."""
        rng = np.random.default_rng(int(self.seed))
        ex = rng.normal(0.0, 1.0, (robot.m, 3)) * self.exit_offset
        ln = np.asarray(rng.normal(0.0, 1.0, robot.m)) * self.length_offset
        # Streams drawn after the original ones so that earlier seeds keep their draws.
        sxy, syaw = self.base_pose
        dpose = rng.normal(0.0, 1.0, (len(robot.bases), 3)) * np.array([sxy, sxy, syaw])
        if sxy > 0.0 or syaw > 0.0:
            from ..kinematics._bases import moved_exits
            nominal = np.array([b.pose for b in robot.bases])
            mobile = np.array([b.mobile for b in robot.bases], dtype=float)[:, None]
            ex = ex + moved_exits(robot, (nominal + mobile * dpose)[None])[0] \
                - robot.exits_world
        ws = np.clip(1.0 + self.winch * rng.normal(0.0, 1.0, (3, robot.m)), 0.1, 10.0)
        ps = float(np.clip(1.0 + self.payload_mass * rng.normal(), 0.1, 10.0))
        return PlantPerturbation(ex, ln, self.friction_scale, self.mass_scale, ws[0], ws[1],
                                 ws[2], ps)


def stack_perturbations(robot: CableRobot, errors: Any) -> list[PlantPerturbation]:
    """A list of perturbations from ``None``, one :class:`ModelErrors` or a sequence."""
    if errors is None:
        errors = [ModelErrors()]
    elif isinstance(errors, ModelErrors):
        errors = [errors]
    out = []
    for i, e in enumerate(errors):
        if not isinstance(e, ModelErrors):
            raise InvalidInputError(f"model_errors[{i}]", "must be a taut.cdpr.ModelErrors")
        out.append(e.draw(robot))
    if not out:
        raise InvalidInputError("model_errors", "an empty sequence")
    return out
