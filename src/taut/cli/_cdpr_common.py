"""Pieces shared by the `taut cdpr` command modules: loading a model inside the accepted
numeric range and checking poses (all heavy imports happen here, lazily)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .._validate import MAX_CDPR_LENGTH_M, MAX_SPEED, check_range

if TYPE_CHECKING:
    from ..cdpr.model.robot import CableRobot

Vec3 = tuple[float, float, float]
Vec6 = tuple[float, float, float, float, float, float]

#: |roll|, |pitch|, |yaw| accepted on the command line, rad (a few turns; angles are periodic).
MAX_ANGLE_RAD = 100.0

MODEL_HELP = "Preset name (fastkit, ipanema) or model file (YAML/JSON)."


def load_robot(model: str, stabilisers: bool) -> CableRobot:
    """A preset or model file, with the stabilisers of its mobile bases deployed if asked.

    Masses above ``MAX_MASS_KG`` and points farther than ``MAX_CDPR_LENGTH_M`` are rejected
    by the loader itself (:func:`taut.io.cdpr_model.physical_ranges`), so the app and
    the library accept the same files as the CLI."""
    from ..cdpr import with_stabilisers
    from ..io.cdpr_model import load_cdpr_model

    robot = load_cdpr_model(model)
    return with_stabilisers(robot) if stabilisers else robot


def given(**options: Any) -> dict[str, Any]:
    """The options the user gave (not None): those left out take the library's defaults, so
    the command line never decides a default of its own."""
    return {k: v for k, v in options.items() if v is not None}


def pose_vector(pose: Any, rpy: Any) -> np.ndarray:
    """``(x, y, z, roll, pitch, yaw)`` from the ``--pose`` and ``--rpy`` options, in range."""
    p = check_range(pose, "pose", MAX_CDPR_LENGTH_M, "m")
    a = check_range(rpy, "rpy", MAX_ANGLE_RAD, "rad")
    return np.concatenate([p, a])


def speeds(values: Any, field: str) -> np.ndarray:
    """Speeds or twist components (m/s, rad/s) within ``MAX_SPEED``."""
    return check_range(values, field, MAX_SPEED, "m/s or rad/s")
