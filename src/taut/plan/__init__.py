"""Motion planning with obstacle crossing for sheet-carrying robot teams (planning paper,
Hu et al., Sec. IV). Every public name is imported from here (``import taut.plan as tp``).
Lengths in metres, times in seconds, angles in radians.

Scenario and team
-----------------
Obstacle
    An obstacle standing on the ground (a cylinder or a prism) with a height.
World
    The free-space polygon (its boundary is the walls) and its obstacles.
Team
    The sheet, its robots and their physical and motion parameters.
Scenario
    World, team, and the object's start and goal.

Planning
--------
plan
    The one front end: the SE(2) planner with obstacle crossing (default), the disc-model
    roadmap planners (``method="roadmap"``, ``"algorithm2"``) and the bypass-only
    baselines (``baseline="se2"``, ``"disc"``). Its options are validated once
    (:mod:`taut.plan._options`; the accepted ranges are defined in :mod:`taut.plan._tol`).

Formations
----------
Formation
    A rigid formation holding the object stably with every cable taut.
CostWeights
    Weights of the formation cost, eq. (11).
optimal_formation
    One optimal formation, eqs. (11-15).
formation_library
    The formations the SE(2) planner searches with.
crossing_pairs
    Entering/exiting sides of Algorithm 2.
offset_crossings
    Straight crossings at a fixed heading (our extension of Algorithm 2).

Roadmap planner
---------------
Leg, Route
    One leg (move, cross, reform) and a whole route on the disc-model roadmap.
find_route
    Shortest-time route of one formation or several (Sec. IV, Fig. 4).
Motion, CrossingRecord
    Time-stamped team samples along a route; one crossing (Algorithm 2 or straight).
motion_from_legs
    Time a route (Algorithm 2 on crossing legs, formation changes in place).

SE(2) search
------------
No public entry of its own (:mod:`taut.plan.se2`): the planner runs it by default and
for ``baseline="se2"``.

Checks and analyses
-------------------
verify_motion, Verification
    Verify a sampled motion as a continuous motion with the quasi-static model; its
    outcome.
resample_motion
    Denser samples of a motion (rigidly on rigid intervals).
find_certificate, Certificate
    A proof that no plan exists (a cut separating start and goal), when one is found.
plan_profile, PlanProfile
    Per-sample profile of a plan: obstacle beneath the sheet, the object's height over
    it, least sheet slack over robot pairs.
plan_robustness, Robustness
    Failure probabilities of a plan under robot position error (seeded Monte Carlo).
object_feedback, ObjectFeedback
    Closed-loop control of the measured object through the equilibria's Jacobians
    against open loop, under the same robot errors.

Execution
---------
robot_trajectories, RobotTrajectories
    One time-parameterised trajectory per robot (holonomic or differential drive) under
    speed, acceleration and yaw-rate limits, re-verified on the executed motion; its
    outcome.

Suite
-----
generate_scenario, generate_suite
    One seeded cluttered-corridor scenario; a seeded benchmark suite of them.

Results and errors
------------------
PlanResult
    A transport plan, or why there is none.
UnknownObstacleError
    No obstacle has the id asked for.
"""

from .checks.certificate import Certificate, find_certificate
from .checks.feedback import ObjectFeedback, object_feedback
from .checks.profile import PlanProfile, plan_profile
from .checks.robustness import Robustness, plan_robustness
from .checks.verify import Verification, resample_motion, verify_motion
from .execution.trajectories import RobotTrajectories, robot_trajectories
from .formations.library import formation_library
from .formations.optimal import (CostWeights, Formation, crossing_pairs, offset_crossings,
    optimal_formation)
from .planner import plan
from .result import PlanResult
from .roadmap.crossing import CrossingRecord, Motion, motion_from_legs
from .roadmap.route import Leg, Route, find_route
from .suite import generate_scenario, generate_suite
from .world import Obstacle, Scenario, Team, UnknownObstacleError, World

__all__ = [
    # Scenario and team
    "Obstacle", "World", "Team", "Scenario",
    # Planning
    "plan",
    # Formations
    "Formation", "CostWeights", "optimal_formation", "formation_library", "crossing_pairs",
    "offset_crossings",
    # Roadmap planner
    "Leg", "Route", "find_route", "Motion", "CrossingRecord", "motion_from_legs",
    # Checks and analyses
    "Verification", "verify_motion", "resample_motion", "Certificate", "find_certificate",
    "PlanProfile", "plan_profile", "Robustness", "plan_robustness", "ObjectFeedback",
    "object_feedback",
    # Execution
    "robot_trajectories", "RobotTrajectories",
    # Suite
    "generate_scenario", "generate_suite",
    # Results and errors
    "PlanResult", "UnknownObstacleError",
]
