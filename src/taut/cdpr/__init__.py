"""Cable-driven parallel robots on fixed frames and mobile bases (FASTKIT paper, §3-4):
validated models, cable kinematics and the wrench matrix (eq. 18), tension distribution
(eqs. 17, 20), tipping constraints of mobile bases (eqs. 21-23), the exact available wrench
set (eq. 24) with axis capacities and capacity margins, wrench-feasible workspaces;
first-order kinematics of mobile bases and cables (eqs. 1-9), the exact available twist set
(eqs. 10-16), redundancy resolution and deployment planning of the bases.

All quantities are SI (m, kg, N, rad), float64; batched functions take a leading axis of B
poses ``(x, y, z, roll, pitch, yaw)``.
"""

from .kinematics.cables import (CableState, as_poses, cable_state, gravity_wrench,
    rotation_matrices, tipping_matrix, wrench_matrix)
from .model.robot import (Base, Cable, CableRobot, Payload, Platform, check_footprint,
    with_stabilisers)
from .statics.tension import METHODS, TensionResult, distribute_tensions
from .statics.tipping import TippingResult, tipping_moments
from .deployment.deploy import DeploymentResult, plan_deployment
from .deployment.lift import LiftBound, lift_bound, upward_force_bound
from .deployment.placement import place_bases, workspace_box
from .deployment.tallest import TallestWorkspace, tallest_workspace
from .deployment.redundancy import OBJECTIVES, RedundancyResult, resolve_redundancy
from .sets.twist import AvailableTwistSet, TwistCapacities, available_twist_set, twist_capacities
from .kinematics.first_order import FirstOrderModel, first_order_model
from .kinematics.modes import MODES, TWIST_LABELS, MotionLimits, fastkit_motion_limits
from .workspace.wrench_feasible import WorkspaceResult, grid_points, wrench_feasible_workspace
from .sets.wrench import (AXIS_LABELS, AvailableWrenchSet, AxisCapacities, available_wrench_set,
    axis_capacities, capacity_margin, disturbance_box, wrench_feasible)

__all__ = [
    "Base", "Cable", "CableRobot", "Payload", "Platform", "check_footprint", "with_stabilisers",
    "CableState", "as_poses", "cable_state", "gravity_wrench", "rotation_matrices",
    "tipping_matrix", "wrench_matrix",
    "METHODS", "TensionResult", "distribute_tensions",
    "TippingResult", "tipping_moments",
    "WorkspaceResult", "grid_points", "wrench_feasible_workspace",
    "AXIS_LABELS", "AvailableWrenchSet", "AxisCapacities", "available_wrench_set",
    "axis_capacities", "capacity_margin", "disturbance_box", "wrench_feasible",
    "MODES", "TWIST_LABELS", "AvailableTwistSet", "FirstOrderModel", "MotionLimits",
    "TwistCapacities", "available_twist_set", "fastkit_motion_limits", "first_order_model",
    "twist_capacities",
    "OBJECTIVES", "RedundancyResult", "resolve_redundancy",
    "DeploymentResult", "place_bases", "plan_deployment", "workspace_box",
    "LiftBound", "lift_bound", "upward_force_bound", "TallestWorkspace", "tallest_workspace",
]

# Re-exports of every name the submodules' __all__ list (one public import path: taut.cdpr).
from .deployment.deploy import DeploymentOptions, evaluate_deployment  # noqa: E402
from .kinematics.first_order import base_jacobians, parallel_jacobian  # noqa: E402
from .kinematics.modes import BASE_JOINTS, Mode, ModeName, joint_bounds, resolve_mode  # noqa: E402
from .deployment.placement import footprint_overlap  # noqa: E402
from .sets.polytope import HPolytopeBatch, lp_max_step  # noqa: E402
from .statics.tension import QPSolver, TensionMethod  # noqa: E402
from .sets.twist import support  # noqa: E402
from .sets.wrench import external_wrench_box  # noqa: E402
from .sets.zonotope import zonotope_hrep  # noqa: E402

__all__ += [
    "DeploymentOptions", "evaluate_deployment", "base_jacobians", "parallel_jacobian",
    "BASE_JOINTS", "Mode", "ModeName", "joint_bounds", "resolve_mode", "footprint_overlap",
    "HPolytopeBatch", "lp_max_step", "QPSolver", "TensionMethod", "support",
    "external_wrench_box", "zonotope_hrep",
]

from .model.robot import with_friction  # noqa: E402
from .statics.sliding import sliding_rows  # noqa: E402

__all__ += ["with_friction", "sliding_rows"]

from .sets.closure import wrench_closure  # noqa: E402

__all__ += ["wrench_closure"]

from .kinematics.interference import (Interference, cable_interference, segment_distance)  # noqa: E402

__all__ += ["Interference", "cable_interference", "segment_distance"]

# Moving robot: forward kinematics, elastic cables and winches, control simulation (issue 13).
from .kinematics.forward import CableFKResult, cable_forward_kinematics
from .control.dynamics import DynamicsModel
from .control.model_errors import ModelErrors
from .control.references import Reference, pick_and_place, reference_from_samples
from .control.controllers import CONTROLLERS, Controller, TorqueController, VelocityController
from .control.monitors import ControlEvent
from .control.simulate import BaseMotion, ControlResult, MonteCarloResult, monte_carlo, simulate

__all__ += [
    "CableFKResult", "cable_forward_kinematics", "DynamicsModel", "ModelErrors", "Reference",
    "pick_and_place", "reference_from_samples", "CONTROLLERS", "Controller", "TorqueController",
    "VelocityController", "ControlEvent", "BaseMotion", "ControlResult", "MonteCarloResult",
    "monte_carlo", "simulate",
]

from .deployment.moving_base import (MovingDeploymentResult, plan_moving_deployment,
    staged_lift_bound)
from .workspace.exit_box import platform_inside_exits  # noqa: E402

__all__ += ["MovingDeploymentResult", "plan_moving_deployment", "staged_lift_bound",
            "platform_inside_exits"]
