"""Pieces shared by the `taut cdpr` command modules."""

from __future__ import annotations

from ..cdpr import with_stabilisers
from ..cdpr.model import CableRobot
from ..io.cdpr_model import load_cdpr_model

Vec3 = tuple[float, float, float]


def load_robot(model: str, stabilisers: bool) -> CableRobot:
    """A preset or model file, with the stabilisers of its mobile bases deployed if asked."""
    robot = load_cdpr_model(model)
    return with_stabilisers(robot, True) if stabilisers else robot
