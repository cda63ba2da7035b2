"""Model errors between the nominal model a controller uses and the plant it drives (FASTKIT
paper §2.2: "because of ineluctable model errors, cables might get slack or too stretched").

The controller always uses the nominal robot and :class:`DynamicsModel`; the simulated plant
uses the perturbed one drawn here.
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
    """

    exit_offsets: np.ndarray
    length_offsets: np.ndarray
    friction_scale: float
    mass_scale: float


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
        s = self.seed
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 0:
            raise InvalidInputError("model_errors.seed", f"must be a non-negative integer, "
                                                         f"got {s!r}")

    def draw(self, robot: CableRobot) -> PlantPerturbation:
        """Draw this plant's errors for ``robot`` (deterministic in ``seed``)."""
        rng = np.random.default_rng(int(self.seed))
        ex = rng.normal(0.0, 1.0, (robot.m, 3)) * self.exit_offset
        ln = np.asarray(rng.normal(0.0, 1.0, robot.m)) * self.length_offset
        return PlantPerturbation(ex, ln, self.friction_scale, self.mass_scale)


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
