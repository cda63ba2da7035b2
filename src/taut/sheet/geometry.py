"""Formation geometry used by the VVCM motion planner (planning paper, Sec. II-A, eqs. 1-4).

The planning paper (Hu et al., "Multi-Robot Object Transport Motion Planning with a
Deformable Sheet") lost most symbols in our copy of the text; they are rebuilt here from the
prose around each equation:

* eq. (1) formation size :math:`S_f = D_c + 2\\delta_s`, with :math:`D_c` the diameter of the
  minimum circumscribed (enclosing) circle of the robot positions :math:`\\mathbf{r}_i` and
  :math:`\\delta_s` "a constant safety distance at each side of the robotic formation"
  (``margin`` here; one on each side, hence the factor 2);
* eq. (2) maximum traversable obstacle height :math:`h_{max} = z_o - \\delta_h`, with
  :math:`z_o` the object height and :math:`\\delta_h` "a minimum safety distance between the
  object and the obstacle" (``height_margin``);
* eq. (3) shortest inter-robot distance :math:`d_{min} = \\min_{i \\ne j \\in \\mathcal{I}}
  |\\mathbf{r}_i - \\mathbf{r}_j|`, :math:`\\mathcal{I} = \\{1, \\dots, N\\}` (robots are particles);
* eq. (4) maximum traversable obstacle diameter :math:`D_{max} = d_{min} - 2\\delta_s`:
  an obstacle passes under the sheet between two robots, keeping the side safety distance
  from both (our reading; the printed equation is lost). It is reported as computed, so a
  value <= 0 means no obstacle fits between the robots.

All functions take any formation (no feasibility check: the geometry is defined for any
point set) in any length unit, and return values in that unit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_array, as_finite_scalar, as_nonnegative
from ..errors import InvalidInputError
from .._repr import CompactRepr

__all__ = ["FormationMetrics", "formation_metrics", "minimum_enclosing_circle",
           "formation_size", "max_obstacle_height", "min_robot_distance",
           "max_obstacle_diameter"]


def _points(formation: object, field: str = "formation") -> np.ndarray:
    r = as_array(formation, field, ndim=2)
    if r.shape[1] != 2:
        raise InvalidInputError(field, f"last axis must have length 2 (x, y), got {r.shape[1]}")
    if r.shape[0] < 2:
        raise InvalidInputError(field, f"needs at least 2 robots, got {r.shape[0]}")
    return r


def minimum_enclosing_circle(formation: ArrayLike) -> tuple[np.ndarray, float]:
    """Smallest circle containing every robot (GEOS's minimum bounding circle through
    shapely, as for the planner's obstacles in :mod:`taut.plan.world`).

    Parameters
    ----------
    formation : array_like, shape (N, 2)
        Robot positions, N >= 2 (any length unit).

    Returns
    -------
    centre : ndarray, shape (2,)
    radius : float
        Half of :math:`D_c` in the planning paper's eq. (1).
    """
    import shapely

    pts = _points(formation)
    # Relative to the centroid, so that far-off coordinates do not cost precision.
    origin = pts.mean(axis=0)
    cloud = shapely.multipoints(pts - origin)
    radius = float(shapely.minimum_bounding_radius(cloud))
    if radius == 0.0:                     # every robot at one place: GEOS gives no polygon
        return pts[0].copy(), 0.0
    centre = np.array(shapely.minimum_bounding_circle(cloud).centroid.coords[0])
    return centre + origin, radius


def formation_size(formation: ArrayLike, margin: float = 0.0) -> float:
    """Formation size :math:`S_f = D_c + 2\\delta_s` (planning paper eq. 1).

    Parameters
    ----------
    formation : array_like, shape (N, 2)
        Robot positions :math:`\\mathbf{r}_i`.
    margin : float
        Side safety distance :math:`\\delta_s` (>= 0), same unit.
    """
    _, radius = minimum_enclosing_circle(formation)
    return 2.0 * radius + 2.0 * as_nonnegative(margin, "margin")


def max_obstacle_height(object_height: float, height_margin: float = 0.0) -> float:
    """Maximum traversable obstacle height :math:`h_{max} = z_o - \\delta_h` (planning
    paper eq. 2): the object at height :math:`z_o` clears an obstacle of this height by
    the safety distance :math:`\\delta_h` (``height_margin`` >= 0)."""
    return as_finite_scalar(object_height, "object_height") - as_nonnegative(
        height_margin, "height_margin")


def min_robot_distance(formation: ArrayLike) -> tuple[float, tuple[int, int]]:
    """Shortest inter-robot distance :math:`d_{min} = \\min_{i \\ne j} |\\mathbf{r}_i -
    \\mathbf{r}_j|` (planning paper eq. 3).

    Returns
    -------
    distance : float
    pair : tuple of int
        0-based indices ``(i, j)``, ``i < j``, of the closest pair.
    """
    r = _points(formation)
    iu, ju = np.triu_indices(len(r), 1)
    d = np.linalg.norm(r[iu] - r[ju], axis=1)
    k = int(np.argmin(d))
    return float(d[k]), (int(iu[k]), int(ju[k]))


def max_obstacle_diameter(formation: ArrayLike, margin: float = 0.0) -> float:
    """Maximum traversable obstacle diameter :math:`D_{max} = d_{min} - 2\\delta_s`
    (planning paper eq. 4, our reading): an obstacle passing between the two closest robots
    keeps the side safety distance :math:`\\delta_s` (``margin``) from each. <= 0 means
    no obstacle fits."""
    dmin, _ = min_robot_distance(formation)
    return dmin - 2.0 * as_nonnegative(margin, "margin")


@dataclass(frozen=True, eq=False, repr=False)
class FormationMetrics(CompactRepr):
    """The planning paper's formation quantities (eqs. 1-4) for one formation.

    Attributes
    ----------
    centre : ndarray, shape (2,)
        Centre of the minimum enclosing circle.
    enclosing_diameter : float
        :math:`D_c`, diameter of the minimum enclosing circle.
    size : float
        :math:`S_f = D_c + 2\\delta_s` (eq. 1).
    min_distance : float
        :math:`d_{min}` (eq. 3).
    closest_pair : tuple of int
        0-based robots attaining :math:`d_{min}`.
    max_obstacle_diameter : float
        :math:`D_{max} = d_{min} - 2\\delta_s` (eq. 4).
    max_obstacle_height : float or None
        :math:`h_{max} = z_o - \\delta_h` (eq. 2) when an object height was given.
    """

    centre: np.ndarray
    enclosing_diameter: float
    size: float
    min_distance: float
    closest_pair: tuple[int, int]
    max_obstacle_diameter: float
    max_obstacle_height: float | None


def formation_metrics(formation: ArrayLike, *, margin: float = 0.0,
                      object_height: float | None = None, height_margin: float = 0.0
                      ) -> FormationMetrics:
    """All formation quantities of the planning paper's eqs. (1)-(4) at once.

    Parameters
    ----------
    formation : array_like, shape (N, 2)
        Robot positions (any formation; N >= 2).
    margin : float
        Side safety distance :math:`\\delta_s` (eqs. 1 and 4).
    object_height : float, optional
        Object height :math:`z_o` (e.g. ``forward_kinematics(...).lowest.height``).
    height_margin : float
        Object-obstacle safety distance :math:`\\delta_h` (eq. 2).
    """
    r = _points(formation)
    m = as_nonnegative(margin, "margin")
    centre, radius = minimum_enclosing_circle(r)
    dmin, pair = min_robot_distance(r)
    h = None if object_height is None else max_obstacle_height(object_height, height_margin)
    return FormationMetrics(centre, 2.0 * radius, 2.0 * radius + 2.0 * m, dmin, pair,
                            dmin - 2.0 * m, h)
