"""Ground-contact polygons of mobile bases: validation of a footprint (convex, simple,
non-degenerate, returned counter-clockwise as the tipping moments of FASTKIT eqs. 21-23
need). The convex hull of wheels and stabiliser feet is :func:`taut._geometry.convex_hull_2d`.
Units: m."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..._validate import as_points
from ...errors import InvalidModelError
from .._tol import FOOTPRINT_EDGE, FOOTPRINT_TURN, WINDING_RAD

__all__ = ["check_footprint"]


def _cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def check_footprint(vertices: Any, fld: str) -> np.ndarray:
    """Validate a ground-contact footprint and return it counter-clockwise.

    Parameters
    ----------
    vertices : array_like, shape (p, 2)
        Contact points (m) in order around the polygon, either orientation.
    fld : str
        Field name used in error messages.

    Returns
    -------
    ndarray, shape (p, 2)
        The same polygon, counter-clockwise seen from above (the orientation for which the
        FASTKIT tipping moments, eqs. 21-23, are <= 0 when the base is stable).

    Raises
    ------
    InvalidModelError
        Fewer than 3 vertices, repeated or collinear vertices, zero area, non-convex or
        self-intersecting polygon.
    """
    pts = as_points(vertices, fld, dim=2, min_count=1)
    if pts.shape[0] < 3:
        raise InvalidModelError(fld, f"a footprint needs at least 3 contact points, got "
                                     f"{pts.shape[0]}")
    scale = float(np.max(np.ptp(pts, axis=0)))
    if scale <= 0.0:
        raise InvalidModelError(fld, "degenerate footprint: all contact points coincide")
    edges = np.roll(pts, -1, axis=0) - pts
    if np.any(np.linalg.norm(edges, axis=1) <= FOOTPRINT_EDGE * scale):
        raise InvalidModelError(fld, "degenerate footprint: repeated contact points")
    area2 = float(np.sum(_cross2(pts, np.roll(pts, -1, axis=0))))
    if abs(area2) <= FOOTPRINT_EDGE * scale * scale:
        raise InvalidModelError(fld, "degenerate footprint: zero area (collinear points)")
    turn = _cross2(edges, np.roll(edges, -1, axis=0)) * np.sign(area2)
    if np.any(turn <= FOOTPRINT_TURN * scale * scale):
        if np.any(turn < -FOOTPRINT_TURN * scale * scale):
            raise InvalidModelError(fld, "footprint must be convex")
        raise InvalidModelError(fld, "degenerate footprint: three collinear contact points")
    # Convex turns everywhere; a star polygon would wind more than once.
    ang = np.arctan2(_cross2(edges, np.roll(edges, -1, axis=0)),
                     np.sum(edges * np.roll(edges, -1, axis=0), axis=1))
    if abs(abs(float(np.sum(ang))) - 2 * np.pi) > WINDING_RAD:
        raise InvalidModelError(fld, "footprint must be a simple convex polygon "
                                     "(it winds around more than once)")
    return pts if area2 > 0 else pts[::-1].copy()


def inside_convex(poly: np.ndarray, pt: np.ndarray) -> bool:
    edges = np.roll(poly, -1, axis=0) - poly
    return bool(np.all(_cross2(edges, pt[None, :] - poly) > 0))
