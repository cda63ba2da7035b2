"""JSON form of control-simulation results (field names as in :class:`taut.cdpr.ControlResult`
and :class:`taut.cdpr.MonteCarloResult`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..cdpr.sim import ControlResult, MonteCarloResult

__all__ = ["control_result_to_dict", "monte_carlo_to_dict"]


def _list(a: np.ndarray, digits: int = 9) -> Any:
    return np.round(np.asarray(a, dtype=float), digits).tolist()


def control_result_to_dict(r: ControlResult) -> dict[str, Any]:
    """Every field of the result; arrays as nested lists (SI units)."""
    return {
        "success": bool(r.success), "status": r.status, "message": r.message,
        "controller": r.controller,
        "times": _list(r.times), "poses": _list(r.poses), "reference": _list(r.reference),
        "tracking_error": _list(r.tracking_error, 12),
        "orientation_error": _list(r.orientation_error, 12),
        "tensions": _list(r.tensions, 6), "motor_torques": _list(r.motor_torques, 9),
        "motor_speeds": _list(r.motor_speeds, 6), "tipping_margin": _list(r.tipping_margin, 6),
        "base_poses": _list(r.base_poses),
        "events": [{"kind": e.kind, "index": e.index, "name": e.name, "start": e.start,
                    "end": e.end, "worst": e.worst, "limit": e.limit} for e in r.events],
        "t_min": _list(r.t_min), "t_max": _list(r.t_max),
        "cable_names": list(r.cable_names), "edge_names": list(r.edge_names),
        "slack_time": r.slack_time, "worst_over_tension": r.worst_over_tension,
        "worst_under_tension": r.worst_under_tension,
    }


def monte_carlo_to_dict(r: MonteCarloResult) -> dict[str, Any]:
    """Per-run arrays as lists."""
    out: dict[str, Any] = {"controller": r.controller, "message": r.message}
    for name in ("max_tracking_error", "rms_tracking_error", "min_tension", "max_tension",
                 "slack_time", "worst_over_tension", "min_tipping_margin"):
        out[name] = _list(getattr(r, name))
    out["success"] = [bool(x) for x in r.success]
    out["status"] = [str(x) for x in r.status]
    return out
