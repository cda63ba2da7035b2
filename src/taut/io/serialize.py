"""Plain-data (JSON-ready) forms of result objects: every ``--json`` output of the CLI is
built here, so the commands only call an analysis and one of these functions.

Conventions: indices are 0-based; lengths in the model's unit (m for cable robots, the
scenario's unit for sheets); forces in N; a number that is not finite becomes ``null``
(JSON has no ``Infinity``/``NaN``), and :func:`to_json` refuses anything else non-finite,
so the output is always valid JSON. Every document says the unit of each of its numbers:
a unit suffix on the key, its ``"units"`` object, or a unitless key (:mod:`taut.io._json_units`).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

import numpy as np

from ._json_units import units_of

if TYPE_CHECKING:                                  # imported lazily: keep `taut --help` fast
    from ..cdpr.deployment.deploy import DeploymentResult
    from ..cdpr.model.robot import CableRobot
    from ..cdpr.control.simulate import ControlResult, MonteCarloResult
    from ..cdpr.statics.tension import TensionResult
    from ..cdpr.sets.twist import TwistCapacities
    from ..cdpr.workspace.wrench_feasible import WorkspaceResult
    from ..plan.checks.robustness import Robustness
    from ..plan.result import PlanResult
    from ..sheet.ik.inverse import IKResult
    from ..sheet.fk.results import Equilibrium, FKResult
    from ..sheet.sim.simulate import SimulationResult

__all__ = ["to_json", "json_ready", "finite_or_none", "equilibrium_to_dict", "fk_result_to_dict",
           "ik_to_dict", "simulation_to_dict", "plan_to_dict", "tensions_to_dict",
           "wrench_set_to_dict", "workspace_to_dict", "twist_set_to_dict",
           "deployment_to_dict", "equilibria_check_to_dict", "control_result_to_dict",
           "monte_carlo_to_dict", "robustness_to_dict", "mission_to_dict"]

def finite_or_none(x: Any, digits: int | None = None) -> float | None:
    """``float(x)`` (rounded to ``digits`` when given), or ``None`` when not finite.

    Examples
    --------
    >>> finite_or_none(1.23456, 2), finite_or_none(float("inf"))
    (1.23, None)
    """
    if x is None:
        return None
    v = float(x)
    if not math.isfinite(v):
        return None
    return round(v, digits) if digits is not None else v


def json_ready(obj: Any) -> Any:
    """``obj`` as plain JSON data, recursively: arrays and tuples to lists, mapping keys to
    str, numpy scalars to Python, and numbers that are not finite (NaN, inf) to ``None``.

    The one NaN -> ``null`` conversion of taut: the CLI's ``--json`` output, the web app's
    responses and the sweep's tables all go through it.

    Examples
    --------
    >>> import numpy as np
    >>> json_ready({"t": np.array([1.0, np.nan]), "n": np.int64(2)})
    {'t': [1.0, None], 'n': 2}
    """
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_ready(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return finite_or_none(obj)
    return obj


def to_json(obj: Any, *, indent: int | None = 2) -> str:
    """Valid JSON text of a plain-data object (non-finite numbers become ``null``).

    Examples
    --------
    >>> to_json({"t": [1.0, float("nan")]}, indent=None)
    '{"t": [1.0, null]}'
    """
    return json.dumps(json_ready(obj), indent=indent, allow_nan=False)


def _floats(a: Any) -> list[float | None] | None:
    """A float array, flattened, NaN as None (None stays None)."""
    return None if a is None else json_ready(np.asarray(a, float).ravel())


# --- sheet-carrying teams -------------------------------------------------------------------

def equilibrium_to_dict(e: Equilibrium) -> dict[str, Any]:
    """``taut`` is 0-based; lengths in the scenario's unit; tensions in N or None."""
    return {
        "taut": list(e.taut),
        "object": _floats(e.object),
        "contact": _floats(e.contact),
        "weights": _floats(e.weights),
        "tensions": _floats(e.tensions),
        "cable_lengths": _floats(e.cable_lengths),
        "kind": e.kind,
        "stable": e.stable,
    }


def fk_result_to_dict(result: FKResult, length_unit: str | None = None) -> dict[str, Any]:
    """``{"equilibria": [...], "funnel": {...} | null, "method": ..., "units": {...}}``
    (``length_unit``: the scenario's ``units:``, for the ``units`` object)."""
    return {
        "method": result.method,
        "equilibria": [equilibrium_to_dict(e) for e in result.equilibria],
        "funnel": None if result.funnel is None else asdict(result.funnel),
        "units": units_of("fk", length_unit),
    }


def ik_to_dict(r: IKResult, length_unit: str | None = None) -> dict[str, Any]:
    """JSON form of an IK result (robots in order, 0-based lists; ``length_unit`` as in
    :func:`fk_result_to_dict`)."""
    return {
        "formation": [_floats(p) for p in r.formation],
        "object": _floats(r.object),
        "contact": _floats(r.contact),
        "angles": _floats(r.angles),
        "weights": _floats(r.weights),
        "tensions": _floats(r.tensions),
        "cable_lengths": _floats(r.cable_lengths),
        "curvature": finite_or_none(r.curvature),
        "spacing": float(r.spacing),
        "construction": r.construction,
        "unmet": list(r.unmet),
        "units": units_of("ik", length_unit),
    }


def _rows(a: np.ndarray) -> list[list[float | None]]:
    return json_ready(np.asarray(a, float))


def simulation_to_dict(r: SimulationResult, time: np.ndarray | None,
                       length_unit: str | None = None) -> dict[str, Any]:
    """JSON form of a simulation (NaN -> null; taut sets 0-based; ``time`` in s, or None:
    the step index, said so in ``units``; ``length_unit`` as in :func:`fk_result_to_dict`)."""
    units = units_of("simulation", length_unit)
    if time is None:
        time, units["time"] = np.arange(len(r), dtype=float), "step index (no time stamps)"
    return {
        "time": _floats(time),
        "object": _rows(r.object),
        "contact": _rows(r.contact),
        "taut": [list(s) for s in r.taut],
        "tensions": None if r.tensions is None else _rows(r.tensions),
        "events": [{
            "step": e.step, "fraction": e.fraction, "kind": e.kind,
            "taut_before": list(e.taut_before), "taut_after": list(e.taut_after),
            "object_before": _floats(e.object_before),
            "object_after": _floats(e.object_after),
            "drop": finite_or_none(e.drop),
        } for e in r.events],
        "units": units,
    }


def plan_to_dict(r: PlanResult) -> dict[str, Any]:
    """JSON form of a plan: ``success``, ``status``, ``message``, ``planner``, ``times``
    [T], ``robots`` [T][N][2], ``object`` [T][3], ``taut`` [T][k] (0-based), ``crossed``,
    ``bypassed``, plus ``path_length`` (m) and ``duration`` (s) (null on failure) and
    ``search`` (who found an SE(2) plan, null otherwise)."""
    return {
        "success": bool(r.success),
        "status": r.status,
        "message": r.message,
        "planner": r.planner,
        "times": [float(t) for t in r.times],
        "robots": np.asarray(r.robots, dtype=float).tolist(),
        "object": np.asarray(r.object, dtype=float).tolist(),
        "taut": [list(s) for s in r.taut],
        "crossed": list(r.crossed),
        "bypassed": list(r.bypassed),
        "path_length": finite_or_none(r.path_length),
        "duration": finite_or_none(r.duration),
        "search": r.search,
        "sheet_margin": finite_or_none(r.sheet_margin),
        "formations": [f.kind for f in r.formations],
        "margins": _plan_margins(r),
        "units": units_of("plan"),
    }


def _plan_margins(r: PlanResult) -> dict[str, Any] | None:
    """The worst margins of a verified plan (m): object height above what is beneath it,
    robot-centre clearance, sheet slack of the tightest pair; null without a plan."""
    v = r.verification
    if v is None or not r.success:
        return None
    return {"height": finite_or_none(v.min_height_margin),
            "clearance": finite_or_none(v.min_clearance),
            "sheet_slack": finite_or_none(v.min_sheet_slack),
            "max_object_step": finite_or_none(v.max_object_step)}


def robustness_to_dict(rob: Robustness) -> dict[str, Any]:
    """JSON form of a plan's Monte Carlo under robot position error (lengths m)."""
    return {"sigma": rob.sigma, "noise": rob.noise, "trials": rob.trials,
            "tear_probability": rob.tear_probability,
            "drop_probability": rob.drop_probability,
            "contact_probability": rob.contact_probability,
            "collision_probability": rob.collision_probability,
            "failure_probability": rob.failure_probability,
            "unsafe_probability": rob.unsafe_probability,
            "worst_extension": finite_or_none(rob.worst_extension),
            "worst_height_margin": finite_or_none(rob.worst_height_margin),
            "worst_clearance": finite_or_none(rob.worst_clearance),
            "units": units_of("robustness")}


# --- cable-driven parallel robots -----------------------------------------------------------

def tensions_to_dict(robot: CableRobot, pose: np.ndarray, res: TensionResult) -> dict[str, Any]:
    """One pose of a tension distribution (``res`` of one pose; tensions keyed by cable
    name, N): ``feasible`` is the result's ``success``, ``message`` its one line,
    ``binding`` the condition that fails (``""`` when feasible)."""
    names = [c.name for c in robot.cables]
    M = res.tipping_moments
    return {
        "model": robot.name, "pose": _floats(pose), "method": res.method,
        "tipping": res.tipping, "sliding": res.sliding, "feasible": bool(res.success),
        "binding": str(res.binding), "message": res.message,
        "residual": finite_or_none(res.residual),
        "tensions": {n: finite_or_none(v) for n, v in zip(names, res.tensions)},
        "tipping_moments": None if not np.all(np.isfinite(M)) else [float(x) for x in M],
        "tipping_edge_base": [robot.bases[k].name for k in robot.edge_base],
        "units": units_of("tensions"),
    }


def wrench_set_to_dict(robot: CableRobot, pose: np.ndarray,
                       modes: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """Axis capacities (of one pose), margin and half-spaces per constraint set.

    ``modes`` maps ``"tension_limits_only"`` / ``"with_tipping"`` to the analyses' outputs
    ``{"capacities": AxisCapacities, "halfspaces": (H, h), "margin": float,
    "gravity_feasible": bool}``."""
    out: dict[str, Any] = {"model": robot.name, "pose": _floats(pose), "dof": robot.dof,
                           "units": units_of("wrench_set")}
    for key, m in modes.items():
        cap = m["capacities"]
        H, h = m["halfspaces"]
        out[key] = {
            "capacity_positive": {lab: finite_or_none(v, 3)
                                  for lab, v in zip(cap.labels, cap.positive)},
            "capacity_negative": {lab: finite_or_none(v, 3)
                                  for lab, v in zip(cap.labels, cap.negative)},
            "capacity_margin": finite_or_none(m["margin"], 4),
            "gravity_feasible": bool(m["gravity_feasible"]),
            "halfspaces": {"H": np.round(H, 9).tolist(), "h": np.round(h, 9).tolist()},
        }
    return out


def workspace_to_dict(robot: CableRobot, region: np.ndarray, ws: WorkspaceResult,
                      n_points: int, plot: Any = None) -> dict[str, Any]:
    """A wrench-feasible workspace on a grid (feasibility as 0/1 lists)."""
    return {
        "model": robot.name, "grid": list(ws.shape or ()), "box": np.asarray(region).tolist(),
        "orientations": np.asarray(ws.orientations).tolist(), "points": int(n_points),
        "coverage": ws.coverage, "coverage_tipping": ws.coverage_tipping,
        "feasible": ws.feasible.astype(int).tolist(),
        "feasible_tipping": (None if ws.feasible_tipping is None else
                             ws.feasible_tipping.astype(int).tolist()),
        "plot": None if plot is None else str(plot),
        "coverage_sliding": ws.coverage_sliding,
        "coverage_inside_exits": ws.coverage_inside,
        "coverage_closure": ws.coverage_closure,
        "closure": None if ws.closure is None else ws.closure.astype(int).tolist(),
        "binding": None if ws.binding is None else [str(b) for b in ws.binding],
        "units": units_of("workspace")}


def twist_set_to_dict(robot: CableRobot, pose: np.ndarray, mode: str,
                      caps: TwistCapacities, fixed: TwistCapacities | None,
                      facets: int) -> dict[str, Any]:
    """Available twist set capacities (m/s, rad/s) of one pose with the mode's bases moving
    and, in task mode, with every base fixed."""
    out: dict[str, Any] = {
        "model": robot.name, "pose": _floats(pose), "mode": mode,
        "moving": list(caps.mode.names), "labels": list(caps.labels),
        "positive": [finite_or_none(v, 4) for v in caps.positive],
        "negative": [finite_or_none(v, 4) for v in caps.negative]}
    if fixed is not None:
        out["bases_fixed"] = {"positive": [finite_or_none(v, 4) for v in fixed.positive],
                              "negative": [finite_or_none(v, 4) for v in fixed.negative]}
    out["facets"] = int(facets)
    out["units"] = units_of("twist_set")
    return out


def deployment_to_dict(robot: CableRobot, res: DeploymentResult) -> dict[str, Any]:
    """A deployment search: base poses (m, m, rad), margins, the lift certificate."""
    lb = res.lift_bound
    r4 = lambda x: finite_or_none(x, 4)  # noqa: E731
    ok = bool(res.success)
    return {
        "model": robot.name, "workspace": np.asarray(res.workspace).tolist(),
        "success": ok, "status": res.status, "message": res.message, "feasible": ok,
        "refuted": bool(res.refuted),
        "base_poses": {k: [round(float(x), 4) for x in v] for k, v in res.base_poses.items()},
        "margin": r4(res.margin),
        "twist_margin": None if res.twist_margin is None else r4(res.twist_margin),
        "points": int(len(res.points)), "feasible_points": int(res.point_feasible.sum()),
        "evaluations": res.evaluations,
        "lift_bound": None if lb is None else {
            "height": r4(lb.height), "bound": r4(lb.bound), "required": r4(lb.required),
            "weight": r4(lb.weight), "refutes": lb.refutes,
            "per_cable": {c.name: r4(v) for c, v in zip(robot.cables, lb.per_cable)}},
        "units": units_of("deployment")}


def equilibria_check_to_dict(check: Any, length_unit: str | None = None) -> dict[str, Any]:
    """JSON-ready form of an :class:`~taut.physics.EquilibriaCheck` (0-based taut sets,
    lengths in scenario units, ``time_s`` in s, ``sliding`` and ``hold_tolerance`` as
    fractions of the object's weight; per state ``kind`` is taut's verdict and
    ``status``/``message`` the simulation's outcome, with ``settled``, ``difference`` and
    ``moved`` null when it failed; ``length_unit`` as in :func:`fk_result_to_dict`)."""
    def f(a: np.ndarray) -> list[float]:
        return [float(x) for x in np.asarray(a).ravel()]

    return {
        "success": bool(check.success), "status": check.status, "message": check.message,
        "mesh": check.mesh, "ball_radius": check.ball, "hold_tolerance": check.hold_tolerance,
        "states": [{"taut": list(s.taut), "kind": s.kind, "held": s.held,
                    "success": bool(s.success), "status": s.status, "message": s.message,
                    "agrees": s.agrees, "predicted": f(s.predicted), "tied": f(s.tied),
                    "settled": f(s.settled), "difference": f(s.difference),
                    "tied_difference": f(s.tied_difference), "sliding": float(s.sliding),
                    "predicted_sliding": float(s.predicted_sliding),
                    "resolved": bool(s.resolved),
                    "reached": None if s.reached is None else list(s.reached),
                    "basin": float(s.basin),
                    "moved": float(s.moved), "time_s": float(s.time)}
                   for s in check.states],
        "units": units_of("physics", length_unit),
    }


# --- cable robot control simulation (field names as in taut.cdpr.ControlResult) ---


def _rounded_list(a: np.ndarray, digits: int = 9) -> Any:
    return np.round(np.asarray(a, dtype=float), digits).tolist()


def control_result_to_dict(r: "ControlResult") -> dict[str, Any]:
    """Every field of the result; arrays as nested lists (SI units)."""
    return {
        "success": bool(r.success), "status": r.status, "message": r.message,
        "controller": r.controller,
        "times": _rounded_list(r.times), "poses": _rounded_list(r.poses), "reference": _rounded_list(r.reference),
        "tracking_error": _rounded_list(r.tracking_error, 12),
        "orientation_error": _rounded_list(r.orientation_error, 12),
        "tensions": _rounded_list(r.tensions, 6), "motor_torques": _rounded_list(r.motor_torques, 9),
        "motor_speeds": _rounded_list(r.motor_speeds, 6), "tipping_margin": _rounded_list(r.tipping_margin, 6),
        "base_poses": _rounded_list(r.base_poses),
        "events": [{"kind": e.kind, "index": e.index, "name": e.name, "start": e.start,
                    "end": e.end, "worst": e.worst, "limit": e.limit} for e in r.events],
        "t_min": _rounded_list(r.t_min), "t_max": _rounded_list(r.t_max),
        "cable_names": list(r.cable_names), "edge_names": list(r.edge_names),
        "slack_time": r.slack_time, "worst_over_tension": r.worst_over_tension,
        "worst_under_tension": r.worst_under_tension,
        "units": units_of("control"),
    }


def monte_carlo_to_dict(r: "MonteCarloResult") -> dict[str, Any]:
    """Per-run arrays as lists."""
    out: dict[str, Any] = {"controller": r.controller, "message": r.message}
    for name in ("max_tracking_error", "rms_tracking_error", "min_tension", "max_tension",
                 "slack_time", "worst_over_tension", "min_tipping_margin"):
        out[name] = _rounded_list(getattr(r, name))
    out["success"] = [bool(x) for x in r.success]
    out["status"] = [str(x) for x in r.status]
    out["units"] = units_of("monte_carlo")
    return out


def mission_to_dict(r: Any) -> dict[str, Any]:
    """A :class:`taut.cdpr.MissionResult` (SI units in every key; sites 1-based)."""
    return {
        "success": bool(r.success), "status": r.status, "message": r.message,
        "total_time_s": finite_or_none(r.total_time, 6),
        "baseline_total_time_s": finite_or_none(r.baseline_total_time, 6),
        "speedup": finite_or_none(r.speedup, 6),
        "motion_time_s": finite_or_none(r.motion_time, 6),
        "baseline_motion_time_s": finite_or_none(r.baseline_motion_time, 6),
        "served": list(r.served),
        "unserved": [{"task": u.name, "reason": u.reason} for u in r.unserved],
        "sites": [{"site": k + 1, "pose_m_rad": _rounded_list(s.pose, 6), "shelf": s.shelf,
                   "tasks": list(s.task_names)} for k, s in enumerate(r.sites)],
        "routes": [{"success": bool(n.success), "status": n.status, "message": n.message,
                    "duration_s": finite_or_none(n.duration, 6)} for n in r.routes],
        "phases": [{"kind": p.kind, "task": p.task or None, "site": p.site + 1,
                    "start_s": finite_or_none(p.start, 6), "end_s": finite_or_none(p.end, 6),
                    "min_tension_margin_N": finite_or_none(p.min_tension_margin, 6),
                    "min_tipping_margin_Nm": finite_or_none(p.min_tipping_margin, 6),
                    "min_sliding_margin_N": finite_or_none(p.min_sliding_margin, 6),
                    "min_cable_clearance_m": finite_or_none(p.min_cable_clearance, 6),
                    "min_footprint_clearance_m": finite_or_none(p.min_footprint_clearance,
                                                                6),
                    "success": bool(p.success), "message": p.message} for p in r.phases],
        "repositions": [{"task": x.task, "offset_m": finite_or_none(x.offset, 6),
                         "motion_time_change_s": finite_or_none(x.saved, 6),
                         "move_time_s": finite_or_none(x.move_time, 6),
                         "best_saving_s": finite_or_none(x.best_saving, 6)}
                        for x in r.repositions],
    }
