"""Motion planning with obstacle crossing for sheet-carrying robot teams (planning paper,
Hu et al., Sec. IV): world and team models, optimal formations (eqs. 11-15), the crossing
motion (Algorithm 2), a global route search, verification by the quasi-static model, a
bypass-only baselines, certificates of impossibility, an SE(2) search over a formation
library and a seeded scenario suite."""

from .baseline import plan_baseline
from .crossing import CrossingRecord, Motion, motion_from_legs
from .formation import (CostWeights, Formation, crossing_pairs, offset_crossings,
                        optimal_formation)
from .certificate import Certificate, find_certificate
from .planner import formation_library, plan
from .result import PlanResult, Robustness
from .route import Leg, Route, find_route
from .suite import generate_scenario, generate_suite
from .verify import Verification, resample_motion, verify_motion
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

# Re-exports of every name the submodules' __all__ list (one public import path: taut.plan).
from .crossing import STEP, TURN_STEP  # noqa: E402
from .formation import MIN_DEPTH_FRACTION  # noqa: E402
from .planner import MAX_CLASSES  # noqa: E402
from .result import attempt, compact_formation, failure  # noqa: E402
from .robustness import monte_carlo  # noqa: E402
from .route import DIRECTIONS, crossable, reform_time  # noqa: E402
from .verify import TOLERANCE  # noqa: E402
from .world import CIRCLE_SEGMENTS  # noqa: E402

__all__ += ["STEP", "TURN_STEP", "MIN_DEPTH_FRACTION", "MAX_CLASSES", "attempt",
            "compact_formation", "failure", "monte_carlo", "DIRECTIONS", "crossable",
            "reform_time", "TOLERANCE", "CIRCLE_SEGMENTS"]
