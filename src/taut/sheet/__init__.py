"""Robot teams holding a deformable sheet that carries an object (virtual variable cables
model, VVCM): models, forward kinematics."""

from .fk import METHODS, forward_kinematics, forward_kinematics_batch
from .model import Sheet, check_formation, check_formations
from .results import GRAVITY, BatchFKResult, Equilibrium, FKResult, Funnel

__all__ = [
    "Sheet", "check_formation", "check_formations",
    "forward_kinematics", "forward_kinematics_batch", "METHODS",
    "FKResult", "BatchFKResult", "Equilibrium", "Funnel", "GRAVITY",
]
