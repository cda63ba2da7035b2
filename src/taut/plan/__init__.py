"""Motion planning with obstacle crossing for sheet-carrying robot teams (planning paper,
Hu et al., Sec. IV): world and team models, optimal formations (eqs. 11-15), the crossing
motion (Algorithm 2), a global route search, verification by the quasi-static model, a
bypass-only baselines, certificates of impossibility, an SE(2) search over a formation
library and a seeded scenario suite."""

from .baseline import plan_baseline
from .roadmap.crossing import CrossingRecord, Motion, motion_from_legs
from .formations.optimal import (CostWeights, Formation, crossing_pairs, offset_crossings,
    optimal_formation)
from .checks.certificate import Certificate, find_certificate
from .planner import formation_library, plan
from .result import PlanResult, Robustness
from .roadmap.route import Leg, Route, find_route
from .suite import generate_scenario, generate_suite
from .checks.verify import Verification, resample_motion, verify_motion
from .world import Obstacle, Scenario, Team, UnknownObstacleError, World

__all__ = [
    "plan", "plan_baseline", "PlanResult",
    "Obstacle", "World", "Team", "Scenario",
    "Formation", "CostWeights", "optimal_formation", "crossing_pairs", "offset_crossings",
    "Leg", "Route", "find_route", "Motion", "CrossingRecord", "motion_from_legs",
    "Verification", "verify_motion", "generate_scenario", "generate_suite",
    "Certificate", "find_certificate", "formation_library", "Robustness", "resample_motion",
    "UnknownObstacleError",
]

