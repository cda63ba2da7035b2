"""Robot teams holding a deformable sheet that carries an object (virtual variable cables
model, VVCM): model, forward and inverse kinematics, quasi-static simulation, formation
geometry."""

from .fk.forward import METHODS, forward_kinematics, forward_kinematics_batch
from .geometry import (FormationMetrics, formation_metrics, formation_size,
                       max_obstacle_diameter, max_obstacle_height, min_robot_distance,
                       minimum_enclosing_circle)
from .ik.inverse import (IKConstraints, IKResult, contact_weights, formation_from_angles,
    ik_constraints, inverse_kinematics)
from .model import Sheet, check_formation, check_formations
from .fk.results import GRAVITY, BatchFKResult, Equilibrium, FKResult, Funnel
from .sim.simulate import SimulationEvent, SimulationResult, simulate
from .fk.solver import FKSolver
from .ik.inverse import IKCertificate
from .sim.simulate import SimulatorState
from .sim.simulator import Simulator

__all__ = [
    "Sheet", "check_formation", "check_formations",
    "forward_kinematics", "forward_kinematics_batch", "METHODS",
    "FKResult", "BatchFKResult", "Equilibrium", "Funnel", "GRAVITY",
    "inverse_kinematics", "IKResult", "IKConstraints", "formation_from_angles",
    "ik_constraints", "contact_weights",
    "simulate", "SimulationResult", "SimulationEvent",
    "formation_metrics", "FormationMetrics", "minimum_enclosing_circle", "formation_size",
    "max_obstacle_height", "min_robot_distance", "max_obstacle_diameter",
    "FKSolver",
    "IKCertificate", "Simulator", "SimulatorState",
]

# Re-exports of every name the submodules' __all__ list (one public import path: taut.sheet).
from .fk.forward import Method  # noqa: E402
from .model import check_hold_height  # noqa: E402
from .random import random_convex_polygon, random_scattered_team, random_team  # noqa: E402
from .fk.results import Status  # noqa: E402
from .sim.simulate import EventKind  # noqa: E402
from .fk.solver import COMPILED_MAX_N, HAVE_NUMBA, Backend  # noqa: E402

__all__ += ["Method", "check_hold_height", "random_convex_polygon", "random_scattered_team",
            "random_team", "Status", "EventKind", "COMPILED_MAX_N", "HAVE_NUMBA", "Backend"]
