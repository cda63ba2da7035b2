"""Plain-data (JSON-ready) forms of result objects, for the CLI's ``--json`` output."""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

import numpy as np

from ..sheet.results import Equilibrium, FKResult

__all__ = ["equilibrium_to_dict", "fk_result_to_dict"]


def _floats(a: np.ndarray | None) -> list[float] | None:
    return None if a is None else [float(x) for x in np.asarray(a).ravel()]


def equilibrium_to_dict(e: Equilibrium) -> dict[str, Any]:
    """``taut`` is 0-based; lengths in the scenario's unit; tensions in N or None."""
    return {
        "taut": list(e.taut),
        "object": _floats(e.object),
        "contact": _floats(e.contact),
        "weights": _floats(e.weights),
        "tensions": _floats(e.tensions),
        "cable_lengths": _floats(e.cable_lengths),
        "status": e.status,
        "stable": e.stable,
    }


def fk_result_to_dict(result: FKResult) -> dict[str, Any]:
    """``{"equilibria": [...], "funnel": {...} | null, "method": ...}``."""
    return {
        "method": result.method,
        "equilibria": [equilibrium_to_dict(e) for e in result.equilibria],
        "funnel": None if result.funnel is None else asdict(result.funnel),
    }
