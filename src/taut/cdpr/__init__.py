"""
Parallel cable robots, fixed and mobile (:mod:`taut.cdpr`)
===========================================================

.. currentmodule:: taut.cdpr

Parallel robots whose platform hangs from cables (CDPRs), on fixed frames and on
mobile bases, after the FASTKIT paper: validated models; cable kinematics, the wrench
matrix (eq. 18) and first-order kinematics of the bases (eqs. 1-9); tension distribution
(eqs. 17, 20) with the tipping constraints of mobile bases (eqs. 21-23) and their friction;
the exact available wrench set (eq. 24) and twist set (eqs. 10-16); wrench-feasible
workspaces; deployment planning of the bases; control simulation of the moving robot
(§2.2).

All quantities are SI (m, kg, N, rad, s), float64. Batched functions take a leading axis of
B poses ``(x, y, z, roll, pitch, yaw)``; one pose gives results without it. Every name
below is importable from ``taut.cdpr`` (the one public import path).

Model
-----

   CableRobot -- a validated robot: bases, platform, cables, payload, limits
   Base -- a fixed frame or a mobile base with its exit points and footprint
   Platform -- the moving platform: attachment points, mass, inertia
   Payload -- the load carried by the platform
   Cable -- one cable from a base's exit point to a platform attachment point
   check_footprint -- validate a convex ground footprint polygon
   with_stabilisers -- the robot with its bases' stabilisers deployed (or retracted)
   with_base_acceleration -- the robot with its mobile bases accelerating (d'Alembert loads)
   with_friction -- the robot with a ground friction coefficient on its mobile bases

Kinematics
----------

   as_poses -- validate poses as a (B, 6) array
   rotation_matrices -- platform rotations from roll, pitch, yaw
   CableState -- cable vectors, lengths, unit vectors and wrench matrices at poses
   cable_state -- compute the cable state at poses (FASTKIT eq. 18)
   wrench_matrix -- the wrench matrix W at poses
   gravity_wrench -- the weight wrench of platform and payload
   tipping_matrix -- edge-moment rows of the cable forces (eqs. 21-23)
   CableFKResult -- outcome of forward kinematics from cable lengths
   cable_forward_kinematics -- platform poses from cable lengths
   FirstOrderModel -- parallel and base Jacobians at poses (eqs. 1-9)
   first_order_model -- compute the first-order model at poses
   parallel_jacobian -- the parallel Jacobian A (eqs. 1-3)
   base_jacobians -- each base as a virtual RPP chain (eqs. 4-9)
   MODES -- the operating modes, task and navigation
   ModeName -- type of a mode name
   Mode -- a resolved mode: which bases move
   resolve_mode -- check a mode and its moving bases against a model
   MotionLimits -- joint velocity limits of bases and cables
   fastkit_motion_limits -- FASTKIT's limits (eqs. 10-16)
   joint_bounds -- joint-rate bounds of a mode
   TWIST_LABELS -- names of the twist components
   BASE_JOINTS -- names of a base's joints
   Interference -- cable-cable and cable-platform clearances
   cable_interference -- clearances at poses
   segment_distance -- distance between line segments

Statics
-------

   distribute_tensions -- cable tensions balancing the platform (eqs. 17, 20-23)
   TensionResult -- its outcome: tensions, success, the binding condition, message
   METHODS -- the tension distribution methods
   TensionMethod -- type of a method name
   QPSolver -- type of a quadratic-programme solver name
   tipping_moments -- edge moments of the mobile bases (eqs. 21-23)
   TippingResult -- moments, stability per pose and per base
   sliding_rows -- friction-pyramid constraints of the mobile bases

Wrench and twist sets
---------------------

   available_wrench_set -- the exact available wrench set (eq. 24)
   AvailableWrenchSet -- its H-representation at B poses
   wrench_feasible -- exact wrench feasibility of poses
   axis_capacities -- largest extra wrench along each axis (Fig. 14)
   AxisCapacities -- their values
   AXIS_LABELS -- names of the wrench axes
   capacity_margin -- distance of a required wrench set to the boundary
   external_wrench_box -- vertices of a box of extra external wrenches
   wrench_closure -- wrench closure (positive tensions, no limits)
   available_twist_set -- the exact available twist set (eqs. 10-16)
   AvailableTwistSet -- its H-representation at B poses
   twist_capacities -- largest speed along each axis (Fig. 13)
   TwistCapacities -- their values
   support -- the twist set's extent along a direction, at one pose
   HPolytopeBatch -- batched H-polytopes behind both sets
   lp_max_step -- the linear programme of a ray length
   zonotope_hrep -- facets of batched zonotopes

Workspaces
----------

   grid_points -- a regular grid over a box
   wrench_feasible_workspace -- wrench-feasible positions, binding condition per position
   WorkspaceResult -- its outcome
   platform_inside_exits -- whether the platform stays inside the exits' box

Deployment
----------

   plan_deployment -- where to park the mobile bases for a workspace box
   DeploymentResult -- its outcome
   DeploymentOptions -- search settings
   evaluate_deployment -- score one placement
   place_bases -- the robot with its mobile bases moved
   workspace_box -- validate a workspace box
   footprint_overlap -- overlap of the base footprints with a box
   lift_bound -- placement-independent certificate on the cables' lift
   LiftBound -- its outcome
   upward_force_bound -- largest upward cable force at poses
   tallest_workspace -- tallest box with a verified deployment
   TallestWorkspace -- its outcome
   plan_moving_deployment -- placements for an active base moving during the task
   MovingDeploymentResult -- its outcome
   plan_base_drive -- a base driving on its wheels, stabilisers deployed once in place
   BaseDrivePlan -- its outcome
   staged_lift_bound -- the lift certificate per stage
   resolve_redundancy -- joint rates for a desired platform twist
   RedundancyResult -- its outcome
   OBJECTIVES -- the redundancy objectives

Control
-------

   simulate -- a controller driving the robot along a reference (§2.2)
   ControlResult -- its outcome: histories, monitors, events
   monte_carlo -- seeded runs batched through one plant
   reference_simulate -- the same run on an RK4 reference integrator (verification)
   MonteCarloResult -- per-run summaries
   Backend -- type of the loop backend name (numba or numpy)
   BaseMotion -- base poses over time (deployment, eq. 8)
   DynamicsModel -- elastic cables and winches (Table 1)
   ModelErrors -- seeded errors of the plant against the model
   Sensing -- what the controller measures (encoders by default)
   Reference -- a platform trajectory
   pick_and_place -- straight moves between waypoints
   reference_from_samples -- a trajectory from sampled poses
   Controller -- base of the controllers (optional: name, mode, command() make one)
   VelocityController -- cable-length control
   TorqueController -- task-space PD on the reference tension distribution
   ComputedTorqueController -- computed-torque control (inverse dynamics at the estimated state)
   CONTROLLERS -- the built-in controllers by name
   tune_for_rate -- built-in gains for another control rate and latency (one delay rule)
   ControlEvent -- one limit episode of a run

Mission
-------

   Warehouse -- the floor, shelves, start and tasks of a mobile cable robot's mission
   Shelf -- a rack or station footprint the bases keep off
   Task -- a box to move from a pick point to a place point
   coupled_footprint -- the rigid footprint of the coupled bases (navigation mode)
   to_robot_frame -- world points in the robot frame of the coupled bases at a pose
   to_world_frame -- robot-frame points in the world
   plan_navigation -- a verified route of the coupled bases between two poses
   NavigationResult -- its outcome: timed poses, or a refusal with a certificate
   NavigationCertificate -- what a refusal proves
   choose_sites -- deployment sites serving the tasks (greedy set cover)
   SitesResult -- its outcome: sites and unserved tasks
   Site -- one deployment: pose, deployed robot, tasks and platform targets
   UnservedTask -- a task no site serves, and why
   time_optimal_path -- time-optimal platform motion through waypoints (TOPP-RA)
   TimedPath -- its outcome: the sampled law, speed limits, acceleration bounds
   with_box -- the robot carrying a box of a given mass as its payload
   plan_mission -- the whole mission planned and simulated, with its 1 m/s baseline
   MissionResult -- its outcome: phases, total and baseline times, unserved tasks
   Phase -- one phase: kind, task, times, margins
   Reposition -- one task's choice of active-base offset along the shelf face
   moving_carry -- a time-optimal carry with the active base driving along the face
   MovingCarry -- its outcome: the law, the bases' motion and accelerations
   run_moving_carry -- that carry in the control simulation, monitored as a phase
   wheels_for_active -- the robot with the active base's stabilisers up (it drives)
   PHASE_KINDS -- the kinds of phase
"""

from .model.parts import Base, Cable, Payload, Platform
from .model.footprint import check_footprint
from .model.robot import CableRobot, with_base_acceleration, with_friction, with_stabilisers
from .kinematics.cables import (CableState, as_poses, cable_state, gravity_wrench,
    rotation_matrices, tipping_matrix, wrench_matrix)
from .kinematics.forward import CableFKResult, cable_forward_kinematics
from .kinematics.first_order import (FirstOrderModel, base_jacobians, first_order_model,
    parallel_jacobian)
from .kinematics.modes import (BASE_JOINTS, MODES, TWIST_LABELS, Mode, ModeName, MotionLimits,
    fastkit_motion_limits, joint_bounds, resolve_mode)
from .kinematics.interference import Interference, cable_interference, segment_distance
from .statics.tension import METHODS, QPSolver, TensionMethod, TensionResult, distribute_tensions
from .statics.tipping import TippingResult, tipping_moments
from .statics.sliding import sliding_rows
from .sets.wrench import (AXIS_LABELS, AvailableWrenchSet, AxisCapacities, available_wrench_set,
    axis_capacities, capacity_margin, external_wrench_box, wrench_feasible)
from .sets.closure import wrench_closure
from .sets.twist import (AvailableTwistSet, TwistCapacities, available_twist_set, support,
    twist_capacities)
from .sets.polytope import HPolytopeBatch, lp_max_step
from .sets.zonotope import zonotope_hrep
from .workspace.wrench_feasible import WorkspaceResult, grid_points, wrench_feasible_workspace
from .workspace.exit_box import platform_inside_exits
from .deployment.deploy import (DeploymentOptions, DeploymentResult, evaluate_deployment,
    plan_deployment)
from .deployment.placement import footprint_overlap, place_bases, workspace_box
from .deployment.lift import LiftBound, lift_bound, upward_force_bound
from .deployment.tallest import TallestWorkspace, tallest_workspace
from .deployment.moving_base import (BaseDrivePlan, MovingDeploymentResult, plan_base_drive,
                                     plan_moving_deployment,
    staged_lift_bound)
from .deployment.redundancy import OBJECTIVES, RedundancyResult, resolve_redundancy
from .control.simulate import (Backend, BaseMotion, ControlResult, MonteCarloResult,
    monte_carlo, simulate)
from .control.reference_integrator import reference_simulate
from .control.dynamics import DynamicsModel
from .control.model_errors import ModelErrors
from .control.sensing import Sensing
from .control.references import Reference, pick_and_place, reference_from_samples
from .control.controllers import (CONTROLLERS, ComputedTorqueController, Controller,
                                  TorqueController, VelocityController, tune_for_rate)
from .control.monitors import ControlEvent
from .mission.warehouse import (Shelf, Task, Warehouse, coupled_footprint, to_robot_frame,
                                to_world_frame)
from .mission.navigation import NavigationCertificate, NavigationResult, plan_navigation
from .mission.sites import Site, SitesResult, UnservedTask, choose_sites
from .mission.timing import TimedPath, time_optimal_path, with_box
from .mission.mission import PHASE_KINDS, MissionResult, Phase, plan_mission
from .mission._reposition import Reposition
from .mission.moving_carry import MovingCarry, moving_carry, run_moving_carry, wheels_for_active

__all__ = [
    # Model
    "CableRobot", "Base", "Platform", "Payload", "Cable", "check_footprint",
    "with_stabilisers", "with_friction", "with_base_acceleration",
    # Kinematics
    "as_poses", "rotation_matrices", "CableState", "cable_state", "wrench_matrix",
    "gravity_wrench", "tipping_matrix", "CableFKResult", "cable_forward_kinematics",
    "FirstOrderModel", "first_order_model", "parallel_jacobian", "base_jacobians", "MODES",
    "ModeName", "Mode", "resolve_mode", "MotionLimits", "fastkit_motion_limits",
    "joint_bounds", "TWIST_LABELS", "BASE_JOINTS", "Interference", "cable_interference",
    "segment_distance",
    # Statics
    "distribute_tensions", "TensionResult", "METHODS", "TensionMethod", "QPSolver",
    "tipping_moments", "TippingResult", "sliding_rows",
    # Wrench and twist sets
    "available_wrench_set", "AvailableWrenchSet", "wrench_feasible", "axis_capacities",
    "AxisCapacities", "AXIS_LABELS", "capacity_margin", "external_wrench_box",
    "wrench_closure", "available_twist_set", "AvailableTwistSet", "twist_capacities",
    "TwistCapacities", "support", "HPolytopeBatch", "lp_max_step", "zonotope_hrep",
    # Workspaces
    "grid_points", "wrench_feasible_workspace", "WorkspaceResult", "platform_inside_exits",
    # Deployment
    "plan_deployment", "DeploymentResult", "DeploymentOptions", "evaluate_deployment",
    "place_bases", "workspace_box", "footprint_overlap", "lift_bound", "LiftBound",
    "upward_force_bound", "tallest_workspace", "TallestWorkspace", "plan_moving_deployment",
    "plan_base_drive", "BaseDrivePlan",
    "MovingDeploymentResult", "staged_lift_bound", "resolve_redundancy", "RedundancyResult",
    "OBJECTIVES",
    # Control
    "simulate", "ControlResult", "monte_carlo", "MonteCarloResult", "reference_simulate",
    "Backend", "BaseMotion",
    "DynamicsModel", "ModelErrors", "Sensing", "Reference", "pick_and_place",
    "reference_from_samples", "Controller", "VelocityController", "TorqueController", "ComputedTorqueController",
    "CONTROLLERS", "tune_for_rate", "ControlEvent",
    # Mission
    "Warehouse", "Shelf", "Task", "coupled_footprint", "to_robot_frame", "to_world_frame",
    "plan_navigation", "NavigationResult", "NavigationCertificate", "choose_sites",
    "SitesResult", "Site", "UnservedTask", "time_optimal_path", "TimedPath", "with_box",
    "plan_mission", "MissionResult", "Phase", "PHASE_KINDS", "Reposition",
    "moving_carry", "MovingCarry", "run_moving_carry", "wheels_for_active",
]
