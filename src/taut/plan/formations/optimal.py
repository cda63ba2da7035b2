"""Optimal formation generation (planning paper Sec. IV-A, eqs. 11-15, rebuilt).

Most symbols of eqs. (11)-(15) are lost in our copy of the paper; this is what we rebuilt
from the prose, and why.

Decision variables (the IK parameters of eq. 10): the contact point :math:`\\mathbf{v}_o`,
the object height :math:`z_o`, one cable angle :math:`\\theta_i` per robot, the vertical load
shares :math:`w_i` and an auxiliary radius :math:`\\bar R` bounding the formation. The object's
projection is the formation's origin; robot ``i`` stands at
:math:`\\mathbf{r}_i = \\rho_i(\\cos\\theta_i, \\sin\\theta_i)`,
:math:`\\rho_i = \\sqrt{|\\mathbf{v}_i - \\mathbf{v}_o|^2 - (z_r - z_o)^2}` (eq. 10).

Cost (eq. 11) :math:`J = J_t + J_p + J_c` with

* transport, eq. (12): :math:`J_t = \\alpha_t \\overline{((\\rho_i - \\rho_i^0)/s)^2} +
  \\beta_t \\sum_i (w_i - 1/N)^2`: stay close to the nominal all-taut formation
  :math:`\\rho^0` (IK at the sheet centroid) and share the load evenly, so every robot
  "participates in the handling" (the paper's motivation for all-taut cables);
* passable area, eq. (13): :math:`J_p = \\alpha_p ((2\\bar R + 2\\delta_s) / W)^2`, the
  formation's size about the object (an upper bound of eq. 1 that also covers rotating
  about the object) relative to the free space's width ``W``;
* crossing, eq. (14): :math:`J_c = \\alpha_c ((z_o - z_{req})/z_r)^2 + \\beta_c
  \\overline{(D_{req}/|\\mathbf{r}_i - \\mathbf{r}_j|)^2}`: hold the object just at the needed
  height (higher objects need wider formations) and keep every robot gap wide so the
  obstacle can enter between any two robots ("cross in any direction").

Constraints: (15b) :math:`h_{max} = z_o - \\delta_h \\ge h_{obs}` and
:math:`D_{max} = d_{min} - 2\\delta_s \\ge D_{obs}` (eqs. 2-4); (15c) formation limits:
every cable taut (:math:`\\rho_i` real), the exact equilibrium conditions of the IK module
(:math:`\\sum w_i = 1`, :math:`\\sum w_i\\mathbf{v}_i = \\mathbf{v}_o`,
:math:`\\sum w_i\\mathbf{r}_i = 0`, :math:`w_i \\ge w_{min}`, positive reduced-Hessian curvature
for N <= 4), the sheet must not tear (:math:`|\\mathbf{r}_i - \\mathbf{r}_j| \\le
|\\mathbf{v}_i - \\mathbf{v}_j|`), robots do not overlap (:math:`\\ge 2` radii), the object
stays above the ground by :math:`\\delta_h` and at least ``MIN_DEPTH_FRACTION`` of
:math:`z_r` below the hands, optionally the reach is bounded (eq. 13 as a hard limit).
Solved with SciPy's SLSQP from the IK solution (``inverse_kinematics`` at the centroid
contact); if SLSQP stalls, the lowest admissible IK formation is taken instead. A result
is accepted only if forward kinematics (an independent solver) finds it as a stable
all-taut equilibrium. Weights: :class:`CostWeights` (crossing height dominates, as the
paper calls :math:`J_c` "the key item").

The nonlinear program itself (decision vector, cost, constraints, nominal IK start) is in
:mod:`taut.plan.formations._problem`; this module holds the formation, its crossing
geometry, and the solve with its independent forward-kinematics acceptance.

Two uses: the *crossing* formation for obstacles up to a height and diameter, and the
*compact* formation (no crossing term, large :math:`\\alpha_p`) for bypassing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from ...errors import TautError
from ...sheet import forward_kinematics, formation_metrics, ik_constraints
from .. import _tol
from .._tol import MAX_SHEET_MARGIN_M
from ._problem import (MIN_DEPTH_FRACTION, CostWeights, _curvature_constraint, _Decision,
    _nominal_ik, _problem)
from ..world import Team
from ..._validate import MAX_SHEET_LENGTH, as_bounded, as_choice, as_count, require_instance
from ..._repr import CompactRepr

__all__ = ["CostWeights", "Formation", "optimal_formation", "crossing_pairs",
           "offset_crossings"]

#: The formations :func:`optimal_formation` designs (its ``kind``).
FormationKind = Literal["crossing", "compact", "narrow"]
FORMATION_KINDS: tuple[str, ...] = ("crossing", "compact", "narrow")


@dataclass(frozen=True, eq=False, repr=False)
class Formation(CompactRepr):
    """A rigid team formation holding the object stably with every cable taut.

    Attributes
    ----------
    robots : ndarray, shape (N, 2)
        Robot positions relative to the object's projection (the formation origin), m.
    object_height : float
        :math:`z_o`, m.
    contact : ndarray, shape (2,)
        :math:`\\mathbf{v}_o` in the sheet frame.
    weights : ndarray, shape (N,)
        Load shares :math:`w_i`.
    kind : {"crossing", "compact", "narrow", "squeezed"}
        What it was designed for (:func:`optimal_formation`'s ``kind``, or a squeezed
        formation of :mod:`taut.plan.formations._squeezed`).
    size : float
        :math:`S_f` of eq. (1) with :math:`\\delta_s` the team's ``clearance``, m.
    max_height : float
        :math:`h_{max}` of eq. (2), m.
    min_distance : float
        :math:`d_{min}` of eq. (3), m.
    max_diameter : float
        :math:`D_{max}` of eq. (4), m.
    reach : float
        Radius about the object of the disc holding every robot footprint plus the lateral
        safety, m: the route keeps this disc off walls and non-crossed obstacles, and it is
        what the formation sweeps when it rotates about the object.
    cost : float
        :math:`J` of eq. (11) at the optimum.
    """

    robots: np.ndarray
    object_height: float
    contact: np.ndarray
    weights: np.ndarray
    kind: str
    size: float
    max_height: float
    min_distance: float
    max_diameter: float
    reach: float
    cost: float

    @property
    def n(self) -> int:
        return int(self.robots.shape[0])

    def placed(self, center: ArrayLike, heading: ArrayLike) -> np.ndarray:
        """Robots (..., N, 2) with the object's projection at ``center`` (..., 2) and the
        formation turned by ``heading`` (...) radians."""
        h = np.asarray(heading, dtype=float)
        c, s = np.cos(h)[..., None], np.sin(h)[..., None]
        x, y = self.robots[:, 0], self.robots[:, 1]
        p = np.asarray(center, dtype=float)[..., None, :]
        out = np.empty(np.broadcast_shapes(c.shape[:-1] + x.shape, p.shape[:-1]) + (2,))
        out[..., 0] = c * x - s * y + p[..., 0]     # the hot path of the SE(2) search:
        out[..., 1] = s * x + c * y + p[..., 1]     # no stacking, no temporary (.., N, 2)
        return out


def _hull_order(p: np.ndarray) -> np.ndarray:
    return np.argsort(np.arctan2(p[:, 1], p[:, 0]))


def crossing_pairs(formation: Formation, clearance: float) -> list[tuple[float, float, float]]:
    """Entering/exiting sides through which an obstacle can pass under the object
    (Algorithm 2's geometry, in the formation frame).

    Sides are the gaps between robots adjacent in angle about the object. The obstacle's
    centre enters along the ray from the object through the side's midpoint (for symmetric
    formations that is the side's normal, as in the paper; the midpoint ray keeps it
    farthest from both robots of the side), reaches the object, the formation turns about
    it, and it leaves along the exiting side's ray. A side is usable when every robot stays
    at least ``clearance`` (obstacle radius + robot radius + lateral safety) from its ray.

    Returns
    -------
    list of (angle_in, angle_out, turn)
        Directions (rad, formation frame) of the entering and exiting rays and the turn
        :math:`\\Delta` (rad, counter-clockwise positive) made at the obstacle, sorted by
        :math:`|\\Delta|`.
    """
    require_instance(formation, Formation, "formation")
    clearance = as_bounded(clearance, "clearance", MAX_SHEET_LENGTH, "m", positive=False)
    return _crossing_pairs(formation, clearance)


def _crossing_pairs(formation: Formation, clearance: float
                    ) -> list[tuple[float, float, float]]:
    """:func:`crossing_pairs` on validated inputs."""
    p = formation.robots
    order = _hull_order(p)
    mids = (p[order] + p[np.roll(order, -1)]) / 2
    dirs = mids / np.linalg.norm(mids, axis=1)[:, None]
    t = np.maximum(p @ dirs.T, 0.0)                         # (N robots, sides)
    dist = np.linalg.norm(p[:, None, :] - t[..., None] * dirs[None], axis=2)
    ok = np.flatnonzero(dist.min(axis=0) >= clearance)
    ang = np.arctan2(dirs[:, 1], dirs[:, 0])
    out = []
    for i in ok:
        for j in ok:
            if i == j:
                continue
            turn = float(np.angle(np.exp(1j * (np.pi - (ang[j] - ang[i])))))
            out.append((float(ang[i]), float(ang[j]), turn))
    out.sort(key=lambda x: abs(x[2]))
    return out


def offset_crossings(formation: Formation, clearance: float, directions: int = 36
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Straight crossings at a fixed heading (our extension of Algorithm 2).

    For a travel direction at angle :math:`\\varphi` in the formation frame, the obstacle's
    centre moves relative to the formation along a line :math:`\\mathbf{n}\\cdot\\mathbf{q}
    = e` (:math:`\\mathbf{n}` the left normal). It keeps ``clearance`` from every robot iff
    :math:`|\\mathbf{n}\\cdot\\mathbf{r}_i - e| \\ge` ``clearance`` for all ``i``; offsets
    strictly between the outermost robots make it pass under the sheet between two robots.
    Algorithm 2's turn at the obstacle is then unnecessary, and the obstacle need not pass
    under the object (useful beside walls). Returns, for each of ``directions`` angles,
    the widest admissible offset interval.

    Returns
    -------
    phi : ndarray, shape (K,)
        Travel directions (rad, formation frame) that admit a crossing.
    lo, hi : ndarray, shape (K,)
        Offset interval :math:`[e_{lo}, e_{hi}]` of the obstacle's path from the object, m.
    """
    require_instance(formation, Formation, "formation")
    clearance = as_bounded(clearance, "clearance", MAX_SHEET_LENGTH, "m", positive=False)
    directions = as_count(directions, "directions", minimum=1, maximum=100_000)
    return _offset_crossings(formation, clearance, directions)


def _offset_crossings(formation: Formation, clearance: float, directions: int = 36
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`offset_crossings` on validated inputs."""
    a = 2 * np.pi * np.arange(directions) / directions
    n = np.column_stack([-np.sin(a), np.cos(a)])
    proj = np.sort(formation.robots @ n.T, axis=0)          # (N, K)
    lo = proj[:-1] + clearance
    hi = proj[1:] - clearance
    width = hi - lo
    k = np.argmax(width, axis=0)
    cols = np.arange(directions)
    ok = width[k, cols] >= 0.0
    return a[ok], lo[k, cols][ok], hi[k, cols][ok]


def optimal_formation(team: Team, *, kind: FormationKind = "crossing", height: float = 0.0,
                      diameter: float = 0.0, width: float | None = None,
                      max_reach: float | None = None, weights: CostWeights | None = None,
                      sheet_margin: float = 0.0) -> Formation | None:
    """Solve the rebuilt eq. (15) for one formation.

    Parameters
    ----------
    team : Team
    kind : {"crossing", "compact", "narrow"}
        ``compact``: minimise the size (bypassing); ``crossing``: eqs. 11-14 in full;
        ``narrow``: minimise the width across the formation's x axis (bypassing in
        corridors: eq. 13 with the half-width in place of the radius).
    height : float
        Tallest obstacle to cross, m (0: none); the object ends at least
        ``height + team.height_safety`` high (15b).
    diameter : float
        Widest obstacle to cross, m: :math:`D_{max}` >= this (15b).
    width : float, optional
        Free-space width ``W`` normalising eq. (13), m (default 4 sheet sizes).
    max_reach : float, optional
        Hard bound on :attr:`Formation.reach`, m (e.g. half the corridor width): the
        passable-area requirement of eq. (13) as a constraint (15c).
    weights : CostWeights, optional
    sheet_margin : float
        Every robot pair stays this far inside its sheet distance, m (robustness to robot
        position error; 0: the paper's constraint).

    Returns
    -------
    Formation or None
        None when no formation meets the constraints.

    Examples
    --------
    >>> import numpy as np
    >>> from taut.sheet import Sheet, SheetTeam
    >>> from taut.plan import Team, optimal_formation
    >>> team = Team(SheetTeam(Sheet.regular(3, 1 / np.sqrt(3)), 0.5), robot_radius=0.15,
    ...             height_safety=0.05, lateral_safety=0.05, speed=0.1, rotation_speed=0.3)
    >>> f = optimal_formation(team, kind="crossing", height=0.2, diameter=0.3)
    >>> round(f.max_height, 6), bool(f.max_diameter >= 0.3 - 1e-9)
    (0.2, True)
    """
    require_instance(team, Team, "team")
    as_choice(kind, FORMATION_KINDS, "kind")
    height = as_bounded(height, "height", MAX_SHEET_LENGTH, "m", positive=False)
    diameter = as_bounded(diameter, "diameter", MAX_SHEET_LENGTH, "m", positive=False)
    sheet_margin = as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_MARGIN_M, "m",
                              positive=False)
    if width is not None:
        width = as_bounded(width, "width", MAX_SHEET_LENGTH, "m", positive=False)
    if max_reach is not None:
        max_reach = as_bounded(max_reach, "max_reach", MAX_SHEET_LENGTH, "m", positive=False)
    if weights is not None:
        require_instance(weights, CostWeights, "weights")
    return _optimal_formation(team, kind, height=height, diameter=diameter, width=width,
                              max_reach=max_reach, weights=weights, sheet_margin=sheet_margin)


def _optimal_formation(team: Team, kind: str, *, height: float = 0.0, diameter: float = 0.0,
                       width: float | None = None, max_reach: float | None = None,
                       weights: CostWeights | None = None, sheet_margin: float = 0.0
                       ) -> Formation | None:
    """:func:`optimal_formation` on validated inputs."""
    prob, start = _problem(team, kind, height, diameter, width, max_reach, weights,
                           float(sheet_margin))
    if prob is None:
        return None
    s = team.sheet.size
    cons = [{"type": "eq", "fun": prob.equalities}, {"type": "ineq", "fun": prob.inequalities}]
    if prob.dec.n <= 4:
        cons.append({"type": "ineq", "fun": _curvature_constraint(team, prob, s)})
    try:
        z = minimize(prob.cost, prob.from_ik(start, s), method="SLSQP", constraints=cons,
                     options={"maxiter": 200, "ftol": _tol.FORMATION_FTOL}).x
    except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
        z = np.full(prob.dec.length, np.nan)
    if np.all(np.isfinite(z)) and prob.admissible(z):
        out = _finish(team, z, prob.dec, s, prob.cost(z), kind)
        if out is not None:
            return out
    # Fallback when SLSQP stalls: the lowest admissible nominal IK formation (the
    # smallest one that meets every constraint), without the cost's refinements.
    for zo in np.linspace(prob.z_lo, prob.z_hi, 25) * s:
        ik = _nominal_ik(team, np.array([zo]))
        if ik is None:
            continue
        z = prob.from_ik(ik, s)
        if prob.admissible(z):
            out = _finish(team, z, prob.dec, s, prob.cost(z), kind)
            if out is not None:
                return out
    return None


def _finish(team: Team, z: np.ndarray, dec: _Decision, s: float, cost: float, kind: str
            ) -> Formation | None:
    """Re-derive the formation exactly from (v_o, z_o, angles) and accept it only when
    forward kinematics finds it as a stable all-taut equilibrium."""
    N = dec.n
    contact, zn, th, _, _ = dec.split(z)
    vo, zo = contact * s, zn * s
    try:
        c = ik_constraints(team.carrier, [0.0, 0.0, zo], th, contact=vo)
    except TautError:
        return None
    robots = c.formation
    try:
        fk = forward_kinematics(team.carrier, robots)
    except TautError:
        return None
    target = np.array([0.0, 0.0, zo])
    match = [e for e in fk.stable if len(e.taut) == N
             and np.linalg.norm(e.object - target) <= _tol.FORMATION_MATCH_RTOL * s]
    if not match:
        return None
    e = match[0]
    m = formation_metrics(robots, margin=team.clearance, object_height=e.height,
                          height_margin=team.height_safety)
    reach = float(np.linalg.norm(robots - e.object[:2], axis=1).max()) + team.clearance
    robots = robots - e.object[:2]
    robots.setflags(write=False)
    w = np.zeros(N)
    w[list(e.taut)] = e.weights
    return Formation(robots, e.height, e.contact, w, kind, m.size,
                     float(m.max_obstacle_height or 0.0), m.min_distance,
                     m.max_obstacle_diameter, reach, float(cost))
