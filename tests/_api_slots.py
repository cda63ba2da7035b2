"""The table behind the slot-by-slot API fuzz (tests/test_api_fuzz_slots.py): every public
callable of ``taut.sheet``, ``taut.plan``, ``taut.cdpr``, ``taut.physics``, ``taut.sweep`` and
``taut.io`` (from ``__all__``) with one valid value for each required argument, so that the
fuzz can replace one argument at a time by a wrong value.

Result containers (frozen dataclasses an analysis returns, never built by a user) and type
aliases are listed in :data:`NOT_CALLED` with the reason.
"""

from __future__ import annotations

import copy
import functools
import importlib
import inspect
from typing import Any, Callable

from pathlib import Path

import numpy as np
from pydantic import BaseModel

ROOT = Path(__file__).parents[1]
WAREHOUSE = ROOT / "examples" / "cdpr" / "warehouse.yaml"
MODULES = ("taut.sheet", "taut.plan", "taut.cdpr", "taut.physics", "taut.sweep", "taut.io")

#: Public names not called by the fuzz, with the reason.
NOT_CALLED: dict[str, str] = {
    **{name: "result container built by an analysis, not by users" for name in (
        "FKResult BatchFKResult Equilibrium Funnel IKResult IKConstraints SimulationResult "
        "SimulationEvent FormationMetrics IKCertificate SimulatorState PlanResult Formation "
        "Leg Route Motion CrossingRecord Verification Certificate Robustness PlanProfile "
        "CableState "
        "TensionResult TippingResult WorkspaceResult AvailableWrenchSet AxisCapacities "
        "AvailableTwistSet FirstOrderModel TwistCapacities RedundancyResult DeploymentResult "
        "LiftBound TallestWorkspace Mode HPolytopeBatch Interference CableFKResult "
        "ControlEvent ControlResult MonteCarloResult SettleResult StateCheck "
        "EquilibriaCheck TippingCheck TippingGridCheck SweepResult SheetScenario "
        "Reference Task MovingDeploymentResult BaseDrivePlan RobotTrajectories "
        "ObjectFeedback").split()},
    **{name: "typing alias (Literal), not a function" for name in
       ("ModeName", "QPSolver", "TensionMethod")},
    "UnknownObstacleError": "an exception class",
    "Controller": "abstract base class (its subclasses are called)",
    **{name: "result container built by an analysis, not by users" for name in
       "NavigationResult NavigationCertificate SitesResult Site UnservedTask".split()},
    **{name: "result container built by an analysis, not by users" for name in
       "TimedPath MissionResult Phase Reposition MovingCarry".split()},
}

#: Callables whose valid call runs a search or a simulation (seconds): only their model
#: and array slots are fuzzed in the fast suite, every slot under ``-m slow``.
HEAVY = frozenset(
    "plan plan_robustness simulate monte_carlo settle replay_equilibria replay_tipping "
    "replay_tipping_grid run_sweep tallest_workspace plan_deployment lift_bound "
    "generate_suite find_route formation_library optimal_formation inverse_kinematics "
    "find_certificate motion_from_legs verify_motion Simulator cable_forward_kinematics "
    "evaluate_chunk plan_moving_deployment staged_lift_bound plan_navigation choose_sites object_feedback "
    "plan_mission time_optimal_path moving_carry run_moving_carry".split())


@functools.lru_cache(maxsize=None)
def fixtures() -> dict[str, Any]:
    """Valid models and data shared by every call (built once)."""
    from taut.cdpr import (cable_state, distribute_tensions, fastkit_motion_limits,
                           pick_and_place, resolve_mode, available_twist_set)
    from taut.io import load_cdpr_model, load_warehouse, plan_scenario_to_mapping
    from taut.plan import generate_scenario, formation_library
    from taut.plan.result import failure
    from taut.sheet import Sheet, SheetTeam, forward_kinematics

    robot = load_cdpr_model("fastkit")
    pose = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    state = cable_state(robot, pose)
    scenario = generate_scenario(0)
    nominal = formation_library(scenario)[0]
    sheet = Sheet.regular(4, 1.0)
    sheet_team = SheetTeam(sheet, 1.0)
    formation = 0.8 * np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    limits = fastkit_motion_limits()
    from taut.sweep.file import load_sweep
    spec = load_sweep(str(ROOT / "examples/sweeps/octagon_stability_small.yaml"))
    return dict(
        robot=robot, pose=pose, state=state, scenario=scenario, nominal=nominal,
        no_plan=failure(scenario, "no plan", "disc"),
        sheet=sheet, sheet_team=sheet_team, formation=formation, limits=limits, spec=spec,
        equilibrium=forward_kinematics(sheet_team, formation).lowest,
        tensions=distribute_tensions(robot, pose).tensions,
        mode=resolve_mode(robot), ats=available_twist_set(robot, pose),
        reference=pick_and_place(robot, [[0, 0, 1.0], [0.05, 0, 1.0]], rate=200.0),
        scenario_map=plan_scenario_to_mapping(scenario),
        warehouse=load_warehouse(WAREHOUSE), fastkit_map=None)


@functools.lru_cache(maxsize=None)
def _carry() -> Any:
    """A short moving-base carry of the FASTKIT preset (planned once)."""
    from taut.cdpr import moving_carry
    return moving_carry(fixtures()["robot"], [[0, 0, 1.0], [0.05, 0, 1.0]], (0.0, 0.02),
                        base_accel=0.25)


@functools.lru_cache(maxsize=None)
def _parsed_warehouse() -> dict[str, Any]:
    """The example warehouse file, parsed once (valid_arguments runs twice per fuzz case)."""
    from taut.io import read_mapping
    return read_mapping(WAREHOUSE)


def _warehouse_map() -> dict[str, Any]:
    """The example warehouse file, parsed: a fresh copy for each call."""
    return copy.deepcopy(_parsed_warehouse())


class _Point(BaseModel):
    """A one-field pydantic model for ``validate_mapping``."""
    x: float


@functools.lru_cache(maxsize=None)
def _fk_result() -> Any:
    """The sheet FK result the recorders write (solved once, as the other fixtures:
    valid_arguments runs twice per fuzz case; the recorders only read it)."""
    from taut.sheet import forward_kinematics
    f = fixtures()
    return forward_kinematics(f["sheet_team"], f["formation"])


def _recording_arguments(suffix: str) -> dict[str, Any]:
    """A sheet FK result to record, its unit and a file in the test's folder."""
    return {"result": _fk_result(), "path": f"{{tmp}}/recording.{suffix}", "length_unit": "m"}


def valid_arguments(module: str, name: str) -> dict[str, Any]:
    """One valid value for each required argument of ``module.name`` (keyword form)."""
    from taut.cdpr import BaseMotion, ModelErrors, Sensing, TorqueController
    f = fixtures()
    base_poses = np.array([b.pose for b in f["robot"].bases], dtype=float)
    box6 = [-0.3, 0.3, -0.1, 0.1, 0.8, 1.2]
    by_name: dict[str, Any] = {
        "sheet": f["sheet"], "formation": f["formation"], "formations": f["formation"][None],
        "hold_height": 1.0, "object_position": (0.0, 0.0, 0.4), "angles": np.zeros(4),
        "object_height": 0.4, "vertices": f["sheet"].vertices,
        "robot": f["robot"], "poses": f["pose"], "pose": f["pose"], "R": f["state"].R,
        "unit": f["state"].unit, "rpy": np.zeros((1, 3)), "tensions": f["tensions"],
        "points": [[0.0, 0.0, 1.0]], "box": box6, "shape": (2, 2, 2), "workspace": box6,
        "half_widths": np.ones(6), "twist": np.zeros(6), "limits": f["limits"],
        "md": f["mode"], "ats": f["ats"], "direction": np.eye(6)[0], "lengths":
        f["state"].lengths[0], "waypoints": [[0, 0, 1.0], [0.05, 0, 1.0]],
        "times": [0.0, 0.1], "reference": f["reference"], "controller": TorqueController(), "sensing": Sensing(),
        "model_errors": [], "friction": 0.5, "deployed": True, "stages": 2,
        "positions": np.zeros((1, len(f["robot"].bases), 3)), "fld": "footprint",
        "scenario": f["scenario"], "team": f["scenario"].team, "clearance": 0.05,
        "carrier": f["sheet_team"],
        "robots": np.zeros((2, f["scenario"].team.sheet.n, 2)),
        "planned_object": np.zeros((2, 3)), "factor": 2, "seed": 0,
        "spec": f["spec"], "start": 0, "stop": 2, "out": "{tmp}/sweep", "path": str(ROOT / "src" / "taut" / "data" / "fastkit.yaml"),
        "source": "fastkit", "data": f["scenario_map"], "obj": {"a": 1},
        "center": np.zeros(6), "gens": np.eye(6), "p0": np.zeros((1, 3)),
        "p1": np.ones((1, 3)), "q0": np.zeros((1, 3)) + [1.0, 0.0, 0.0],
        "q1": np.ones((1, 3)) + [0.0, 1.0, 0.0],
    }
    overrides: dict[tuple[str, str], dict[str, Any]] = {
        ("taut.plan", "crossing_pairs"): {"formation": f["nominal"]},
        ("taut.plan", "offset_crossings"): {"formation": f["nominal"]},
        ("taut.plan", "find_route"): {"formation": f["nominal"]},
        ("taut.plan", "motion_from_legs"): {"formation": f["nominal"]},
        ("taut.plan", "resample_motion"): {"robots": np.zeros((2, 4, 2)),
                                           "planned_object": np.zeros((2, 3))},
        ("taut.plan", "verify_motion"): {},
        ("taut.plan", "plan_profile"): {"result": f["no_plan"]},
        ("taut.plan", "plan_robustness"): {"result": f["no_plan"]},
        ("taut.plan", "object_feedback"): {"result": f["no_plan"]},
        ("taut.sheet", "object_covariance"): {"equilibrium": f["equilibrium"],
                                              "robot_covariance": 1e-6},
        ("taut.plan", "robot_trajectories"): {"result": f["no_plan"], "max_speed": 0.2,
                                              "max_accel": 0.5, "max_yaw_rate": 1.0},
        ("taut.plan", "generate_scenario"): {"seed": 0},
        ("taut.plan", "Obstacle"): {"id": "a", "height": 0.1, "center": (0.0, 0.0),
                                   "radius": 0.1},
        ("taut.plan", "World"): {"free_space": [[0, 0], [5, 0], [5, 5], [0, 5]]},
        ("taut.plan", "Team"): {"carrier": f["sheet_team"],
                               "robot_radius": 0.05, "height_safety": 0.01,
                               "lateral_safety": 0.01, "speed": 0.1,
                               "rotation_speed": 0.1},
        ("taut.plan", "Scenario"): {"world": f["scenario"].world, "team": f["scenario"].team,
                                   "start": f["scenario"].start, "goal": f["scenario"].goal},
        ("taut.cdpr", "Base"): {"name": "b", "exit_points": {"e": (0.0, 0.0, 1.0)}},
        ("taut.cdpr", "Cable"): {"name": "c", "base": "b", "exit": "e", "attachment": "a",
                                "t_min": 1.0, "t_max": 10.0},
        ("taut.cdpr", "CableRobot"): {"bases": f["robot"].bases,
                                     "platform": f["robot"].platform,
                                     "cables": f["robot"].cables},
        ("taut.cdpr", "Platform"): {"attachment_points": {"a": (0.0, 0.0, 0.0)}},
        ("taut.cdpr", "BaseMotion"): {"times": [0.0, 1.0],
                                     "poses": np.zeros((2, len(f["robot"].bases), 3))},
        ("taut.cdpr", "simulate"): {"duration": 0.02},
        ("taut.cdpr", "plan_base_drive"): {"base_motion": BaseMotion(
            times=[0.0, 1.0], poses=np.stack([base_poses, base_poses]))},
        ("taut.cdpr", "monte_carlo"): {"duration": 0.02},
        ("taut.cdpr", "evaluate_deployment"): {"points": np.array([[0.0, 0.0, 1.0]]),
                                              "external_wrench": None, "twists": None,
                                              "moving": None},
        ("taut.cdpr", "grid_points"): {"box": [[-0.3, -0.1, 0.8], [0.3, 0.1, 1.2]]},
        ("taut.cdpr", "place_bases"): {"poses": np.zeros((2, 3))},
        ("taut.cdpr", "base_jacobians"): {"positions": np.array([[0.0, 0.0, 1.0]])},
        ("taut.cdpr", "zonotope_hrep"): {"center": np.zeros((1, 3)), "gens": np.eye(3)[None]},
        ("taut.cdpr", "monte_carlo"): {"duration": 0.02, "model_errors": [ModelErrors()]},
        ("taut.cdpr", "check_footprint"): {"vertices": [[0, 0], [1, 0], [0, 1]]},
        ("taut.cdpr", "with_friction"): {"friction": 0.5},
        ("taut.cdpr", "Warehouse"): {"robot": f["robot"], "floor": f["warehouse"].floor,
                                    "shelves": f["warehouse"].shelves, "start": (4.5, 2.0, 0.0),
                                    "tasks": f["warehouse"].tasks},
        ("taut.cdpr", "Shelf"): {"name": "A", "footprint": [[0, 0], [1, 0], [1, 1], [0, 1]]},
        ("taut.cdpr", "to_robot_frame"): {"pose": (1.0, 2.0, 0.5), "points": [[1.0, 2, 3]]},
        ("taut.cdpr", "to_world_frame"): {"pose": (1.0, 2.0, 0.5), "points": [[1.0, 2, 3]]},
        ("taut.cdpr", "plan_navigation"): {"warehouse": f["warehouse"], "start": (4.5, 2, 0),
                                          "goal": (5.0, 2.0, 0.0)},
        ("taut.cdpr", "choose_sites"): {"warehouse": f["warehouse"]},
        ("taut.cdpr", "time_optimal_path"): {"robot": f["robot"],
                                             "waypoints": [[-0.5, 0, 0.6], [0.5, 0, 0.6]]},
        ("taut.cdpr", "with_box"): {"robot": f["robot"], "mass": 2.0},
        ("taut.cdpr", "with_base_acceleration"): {"acceleration": (0.25, 0.0, 0.0)},
        ("taut.cdpr", "moving_carry"): {"offsets": (0.0, 0.02), "base_accel": 0.25},
        ("taut.cdpr", "run_moving_carry"): {"warehouse": f["warehouse"],
                                            "site_pose": (9.75, 10.05, np.pi),
                                            "carry": _carry()},
        ("taut.cdpr", "plan_mission"): {"warehouse": f["warehouse"]},
        ("taut.io", "load_warehouse"): {"source": str(WAREHOUSE)},
        ("taut.io", "warehouse_from_mapping"): {"data": _warehouse_map()},
        ("taut.cdpr", "lp_max_step"): {"A_eq_x": np.eye(2), "step_col": np.ones(2),
                                      "b_eq": np.zeros(2), "x_bounds": [(0, 1), (0, 1)]},
        ("taut.cdpr", "support"): {"direction": np.eye(6)[0]},
        ("taut.cdpr", "footprint_overlap"): {"box": np.array([[-0.1, -0.1], [0.1, 0.1]])},
        ("taut.cdpr", "reference_from_samples"): {"times": [0.0, 0.1, 0.2],
                                                  "poses": [[0, 0, 1.0, 0, 0, 0]] * 3},
        ("taut.physics", "replay_tipping"): {"pose": f["pose"], "duration": 0.05,
                                             "tensions": f["tensions"][0]},
        ("taut.physics", "replay_tipping_grid"): {"poses": f["pose"], "duration": 0.05},
        ("taut.physics", "settle"): {"max_time": 0.05, "mesh": 4},
        ("taut.physics", "replay_equilibria"): {"mesh": 4},
        ("taut.sweep", "Parameter"): {"name": "hold_height", "values": np.array([1.0])},
        ("taut.sweep", "SweepSpec"): {"task": f["spec"].task, "parameters": f["spec"].parameters},
        ("taut.sweep", "run_sweep"): {"limit": 2},
        ("taut.sweep", "load_sweep"): {
            "path": str(ROOT / "examples/sweeps/octagon_stability_small.yaml")},
        ("taut.sweep", "sweep_from_mapping"): {
            "data": {"task": "plan_suite", "parameters": {"scenario_seed": [0, 1]}}},
        ("taut.sweep", "read_results"): {"folder": "{tmp}"},
        ("taut.sweep", "iter_results"): {"folder": "{tmp}"},
        ("taut.sweep", "results_columns"): {"folder": "{tmp}"},
        ("taut.io", "validate_mapping"): {"model": _Point, "data": {"x": 1.0}},
        ("taut.io", "read_mapping"): {"path": str(ROOT / "examples/sheet/example1.yaml")},
        ("taut.io", "read_text"): {"path": "pyproject.toml"},
        ("taut.io", "write_json"): {"path": "/dev/null"},
        ("taut.io", "write_mcap"): _recording_arguments("mcap"),
        ("taut.io", "write_rerun"): _recording_arguments("rrd"),
        ("taut.io", "parse_mapping"): {"text": "a: 1\n", "source": "inline.yaml"},
        ("taut.io", "write_text_atomic"): {"path": "{tmp}/out.txt", "text": "x"},
        ("taut.io", "load_sheet_scenario"): {"path": str(ROOT / "examples/sheet/example1.yaml")},
        ("taut.io", "load_plan_scenario"): {"path": str(ROOT / "examples/plan/paper_corridor.yaml")},
        ("taut.io", "sheet_scenario_from_mapping"): {"data": {"sheet": [[0, 0], [1, 0],
                                                                        [0, 1]],
                                                               "hold_height": 1.0}},
        ("taut.io", "cdpr_model_from_mapping"): {"data": None},
        ("taut.io", "plan_scenario_to_mapping"): {"scenario": f["scenario"]},
        ("taut.sheet", "random_convex_polygon"): {"n": 4, "rng": np.random.default_rng(0)},
        ("taut.sheet", "random_hanging_team"): {"rng": np.random.default_rng(0)},
        ("taut.sheet", "random_team"): {"n": 4, "rng": np.random.default_rng(0)},
        ("taut.sheet", "random_scattered_team"): {"n": 4, "rng": np.random.default_rng(0)},
        ("taut.sheet", "Simulator"): {"formation": f["formation"]},
        ("taut.sheet", "Sheet"): {"vertices": f["sheet"].vertices},
    }
    if (module, name) == ("taut.io", "cdpr_model_from_mapping"):
        import yaml
        from importlib import resources
        text = resources.files("taut.data").joinpath("fastkit.yaml").read_text()
        return {"data": yaml.safe_load(text)}
    if module == "taut.sheet":                  # a sheet analysis takes the sheet team
        by_name["team"] = f["sheet_team"]
    func = getattr(importlib.import_module(module), name)
    extra = overrides.get((module, name), {})
    out: dict[str, Any] = {}
    for p in inspect.signature(func).parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        if p.name in extra:
            out[p.name] = extra[p.name]
        elif p.default is p.empty:
            out[p.name] = by_name[p.name]
    return out


def public_callables() -> list[tuple[str, str, Callable[..., Any]]]:
    """``(module, name, callable)`` of every public callable the fuzz calls."""
    out = []
    for module in MODULES:
        mod = importlib.import_module(module)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if callable(obj) and name not in NOT_CALLED:
                out.append((module, name, obj))
    return out


def slots(func: Callable[..., Any]) -> list[str]:
    """Names of the arguments the fuzz replaces (every named parameter but callbacks)."""
    return [p.name for p in inspect.signature(func).parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
            and p.name not in ("progress", "field", "fld")]
