"""Robot teams holding a deformable sheet that carries an object (the virtual variable
cables model, VVCM, of Hu et al.): forward and inverse kinematics, quasi-static simulation,
formation geometry. Every public name is imported from here (``import taut.sheet as ts``).

Model
-----
Sheet
    The deformable sheet: a convex polygon whose vertex ``i`` robot ``i`` holds.
SheetTeam
    The model every analysis takes: sheet, common hold height, optional object mass.
check_formation, check_formations
    Validate one formation (N, 2) / a batch (B, N, 2) against the sheet (no pair of robots
    farther apart than its sheet vertices).
check_hold_height
    Validate a hold height (> 0, finite).

Forward kinematics
------------------
forward_kinematics
    Every rest state of the object for one formation (FK paper, Algorithm 1).
forward_kinematics_batch
    The same for many formations at once, as padded arrays.
FKSolver
    Forward kinematics of one team for many formations, with the fixed work done once.
FKResult, BatchFKResult
    The outcomes (``success``, ``status``, ``message``; per formation in a batch).
Equilibrium
    One rest state: taut cables, object, contact point, load shares, tensions, kind.
Funnel
    Step counts of Algorithm 1 (``method="exhaustive"``).
object_covariance
    Object position covariance from robot position covariance through an equilibrium's
    ``jacobian`` (its sensitivities: docs/sheet_sensitivity.md).

Inverse kinematics
------------------
inverse_kinematics
    A formation that holds the object stably at a target, or a proof that none exists.
IKResult
    Its outcome (formation, weights, tensions, ``success``, ``status``, ``message``).
IKCertificate
    A checkable proof that a target is unreachable.
IKConstraints, ik_constraints
    The conditions of an all-taut stable state for given cable angles (for optimisers).
formation_from_angles
    Robot positions from the cable angles (planning paper eq. 10).
contact_weights
    Maximum-entropy load shares of a contact point (barycentric for N = 3).

Simulation
----------
simulate
    Quasi-static simulation of the object along a time series of formations.
Simulator
    The same, one step at a time (for control loops).
SimulationResult, SimulatorState
    A whole run / the state after a step (``success``, ``status``, ``message``).
SimulationEvent, EventKind
    A change during a run (taut set change, jump, object lost or recovered) and its kinds.

Formation geometry
------------------
formation_metrics, FormationMetrics
    Size, obstacle clearance and robot spacing of a formation at once.
minimum_enclosing_circle, formation_size
    The smallest circle around the robots; its diameter plus a margin.
min_robot_distance
    The closest pair of robots.
max_obstacle_height, max_obstacle_diameter
    The largest obstacle the team can pass over / enclose.

Random teams
------------
random_convex_polygon
    A random convex sheet.
random_team
    A random sheet and a feasible formation of it.
random_scattered_team
    A random sheet and robots scattered in any order (the harder case for FK).
random_hanging_team
    A random team, scaled and held so that its object has a rest state (physics samples).

Constants and types
-------------------
GRAVITY
    Gravitational acceleration for tensions, m/s^2.
Method, METHODS
    Forward-kinematics algorithm (``"fast"``, ``"exhaustive"``, ``"subsets"``).
Backend
    Compute backend (``"auto"``, ``"numba"``, ``"numpy"``).
HAVE_NUMBA
    Whether this process runs the compiled kernels (``TAUT_NUMBA``; docs/compiled_kernels.md).
COMPILED_MAX_N
    Largest team for which the compiled solver tries every small subset.
EquilibriumKind
    What a rest state is: ``"stable"``, ``"saddle"``, ``"not_equilibrium"``.

The names above are imported on first use (PEP 562): ``from taut.sheet import
forward_kinematics`` loads neither the inverse kinematics nor the simulation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names
from .._units import GRAVITY
from ._options import METHODS, Backend, Method

if TYPE_CHECKING:                   # the real names, for type checkers
    from .fk.forward import forward_kinematics, forward_kinematics_batch
    from .fk.results import BatchFKResult, Equilibrium, EquilibriumKind, FKResult, Funnel
    from .sensitivity import object_covariance
    from .fk.solver import COMPILED_MAX_N, HAVE_NUMBA, FKSolver
    from .geometry import (FormationMetrics, formation_metrics, formation_size,
                           max_obstacle_diameter, max_obstacle_height, min_robot_distance,
                           minimum_enclosing_circle)
    from .ik.inverse import (IKCertificate, IKConstraints, IKResult, contact_weights,
                             formation_from_angles, ik_constraints, inverse_kinematics)
    from .model import Sheet, check_formation, check_formations, check_hold_height
    from .random import (random_convex_polygon, random_hanging_team, random_scattered_team,
                         random_team)
    from .sim.results import EventKind, SimulationEvent, SimulationResult, SimulatorState
    from .sim.simulate import simulate
    from .sim.simulator import Simulator
    from .team import SheetTeam

_HOME = {
    "forward_kinematics": "fk.forward", "forward_kinematics_batch": "fk.forward",
    "BatchFKResult": "fk.results", "Equilibrium": "fk.results",
    "EquilibriumKind": "fk.results", "FKResult": "fk.results", "Funnel": "fk.results",
    "object_covariance": "sensitivity",
    "COMPILED_MAX_N": "fk.solver", "HAVE_NUMBA": "fk.solver", "FKSolver": "fk.solver",
    "FormationMetrics": "geometry", "formation_metrics": "geometry",
    "formation_size": "geometry", "max_obstacle_diameter": "geometry",
    "max_obstacle_height": "geometry", "min_robot_distance": "geometry",
    "minimum_enclosing_circle": "geometry", "IKCertificate": "ik.inverse",
    "IKConstraints": "ik.inverse", "IKResult": "ik.inverse",
    "contact_weights": "ik.inverse", "formation_from_angles": "ik.inverse",
    "ik_constraints": "ik.inverse", "inverse_kinematics": "ik.inverse", "Sheet": "model",
    "check_formation": "model", "check_formations": "model", "check_hold_height": "model",
    "random_convex_polygon": "random", "random_hanging_team": "random",
    "random_scattered_team": "random", "random_team": "random", "EventKind": "sim.results",
    "SimulationEvent": "sim.results", "SimulationResult": "sim.results",
    "SimulatorState": "sim.results", "simulate": "sim.simulate",
    "Simulator": "sim.simulator", "SheetTeam": "team",
}

__all__ = [
    # Model
    "Sheet", "SheetTeam", "check_formation", "check_formations", "check_hold_height",
    # Forward kinematics
    "forward_kinematics", "forward_kinematics_batch", "FKSolver", "FKResult",
    "BatchFKResult", "Equilibrium", "Funnel", "object_covariance",
    # Inverse kinematics
    "inverse_kinematics", "IKResult", "IKCertificate", "IKConstraints", "ik_constraints",
    "formation_from_angles", "contact_weights",
    # Simulation
    "simulate", "Simulator", "SimulationResult", "SimulatorState", "SimulationEvent",
    "EventKind",
    # Formation geometry
    "formation_metrics", "FormationMetrics", "minimum_enclosing_circle", "formation_size",
    "min_robot_distance", "max_obstacle_height", "max_obstacle_diameter",
    # Random teams
    "random_convex_polygon", "random_team", "random_scattered_team", "random_hanging_team",
    # Constants and types
    "GRAVITY", "Method", "METHODS", "Backend", "HAVE_NUMBA", "COMPILED_MAX_N",
    "EquilibriumKind",
]


__getattr__, __dir__ = lazy_names(__name__, _HOME, globals())
