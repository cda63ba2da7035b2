"""Inverse kinematics of a sheet-carrying team: where must the robots stand so that the
object rests, stably and with every virtual cable taut, at a chosen point?

Planning paper (Hu et al., "Multi-Robot Object Transport Motion Planning with a Deformable
Sheet", Sec. III-B, eq. 10), rebuilt from its prose: with the object at
:math:`\\mathbf{p}_o = (\\mathbf{r}_o, z_o)` resting on the sheet at the contact point
:math:`\\mathbf{v}_o`, cable ``i`` has length :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|` and,
when taut, spans the depth :math:`d = z_r - z_o`, so robot ``i`` stands at

.. math:: \\mathbf{r}_i = \\mathbf{r}_o + \\rho_i (\\cos\\theta_i, \\sin\\theta_i), \\qquad
          \\rho_i = \\sqrt{l_i^2 - d^2}, \\qquad (10)

with a free angle :math:`\\theta_i` per cable. The paper leaves the angles to its optimiser
(eqs. 11-15); here they are fixed by the equilibrium conditions (docs/sheet_kinematics.md
§3-§6):

* weights :math:`w_i > 0`, :math:`\\sum w_i = 1`, :math:`\\sum w_i \\mathbf{v}_i = \\mathbf{v}_o`
  (the contact point fixes them for N = 3; a polytope of dimension N - 3 otherwise);
* horizontal balance :math:`\\sum w_i (\\mathbf{r}_i - \\mathbf{r}_o) = \\sum a_i \\mathbf{u}_i = 0`
  with :math:`a_i = w_i \\rho_i` (proportional to the horizontal tension of cable ``i``);
* stability: the reduced Hessian positive definite (docs/sheet_kinematics.md §5; automatic
  when the tangent-space rows have rank 4, i.e. generic N >= 5);
* the formation is feasible: :math:`|\\mathbf{r}_i - \\mathbf{r}_j| \\le |\\mathbf{v}_i -
  \\mathbf{v}_j|`. This is *not* automatic: two cables whose sheet directions are close can
  be pulled apart horizontally farther than the sheet allows.

Choice within the family (the papers are silent; our documented objective):

1. weights: the maximum-entropy weights of the contact point (:mod:`._ik_weights`);
2. angles: each cable's preferred direction is its sheet direction
   :math:`\\mathbf{v}_i - \\mathbf{v}_o` turned by ``heading``, and the angles maximise the
   tension-weighted alignment :math:`\\sum a_i \\cos(\\theta_i - \\phi_i)` subject to the
   horizontal balance (closed form through a weighted geometric median);
3. if that formation is infeasible or unstable, weights and angles are optimised jointly
   (SLSQP) for the same alignment with every condition as a constraint;
4. if that fails too: a cheap certificate of unreachability is sought (exact triangle for
   N = 3, LP relaxation; :mod:`._ik_certificate`); failing one, (a) a short
   branch-and-bound proof over the cable angles (:mod:`._ik_branch`), (b) a few starts of
   a multi-start search over the structure of the problem, (c) the full branch-and-bound
   proof, (d) the rest of the multi-start search (pair limits included at equality,
   :mod:`._ik_search`).

Every answer is verified with forward kinematics: it has a stable equilibrium with every
cable taut at the target (within VERIFY_RTOL of the sheet size). With ``reference`` (e.g.
the team's current formation), step 3 minimises the total squared robot motion
:math:`\\sum |\\mathbf{r}_i - \\mathbf{r}^{ref}_i|^2` instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import (MAX_IK_ROBOTS, MAX_SHEET_LENGTH, as_array, as_bounded,
    as_finite_scalar, as_nonnegative, check_range)
from ...errors import InvalidInputError
from ._certificate import (IKCertificate, closure_branch_certificate, closure_lp_certificate,
    depth_certificate, radial_certificate, triangle_certificate)
from .results import IKConstraints, IKResult
from ._search import Candidate, check_solution, curvature, joint_optimise, multistart_search
from ._weights import closure_directions, maxent_weights
from .._tol import (CONTACT_INSET_RTOL, DEFAULT_BRANCH_BOXES, DEFAULT_BUDGET, EARLY_BRANCH_BOXES,
    EARLY_SEARCHES, IK_MARGIN_RTOL, MARGIN_SLACK, REFERENCE_MIN_RADIUS, ROBUST_DRAWS,
    ROBUST_REACH, ROBUST_SEED, VERIFY_RTOL)
from ..fk.solver import cached_solver
from ..model import Sheet, feasible_formations
from ..._units import GRAVITY
from ..team import SheetTeam, as_sheet, require_team

__all__ = ["inverse_kinematics", "formation_from_angles", "ik_constraints",
           "contact_weights"]


# --------------------------------------------------------------------------- target

@dataclass(frozen=True)
class _Target:
    """A validated target: object (3,), hold height, depth d, contact (2,), lengths (N,),
    and the normalised frame: V (N, 2) relative to the contact, reach rho (N,) (NaN when
    a cable is shorter than d), both divided by the sheet size ``scale``."""

    p: np.ndarray
    z: float
    d: float
    vo: np.ndarray
    lengths: np.ndarray
    V: np.ndarray
    rho: np.ndarray
    scale: float


def _contact(sheet: Sheet, contact: object | None) -> np.ndarray:
    vo = sheet.centroid if contact is None else as_array(contact, "contact", shape=(2,))
    if not bool(sheet.contains(vo, tol=-CONTACT_INSET_RTOL)):
        raise InvalidInputError("contact", f"contact point ({vo[0]:.6g}, {vo[1]:.6g}) "
                                "is not strictly inside the sheet")
    return vo


def _target(team: SheetTeam, object_position: object, contact: object) -> _Target:
    """Validate a target for a (validated) team; the object must be above the ground and
    the contact strictly inside the sheet (anything else is malformed input)."""
    sheet, z = team.sheet, team.hold_height
    p = as_array(object_position, "object_position", shape=(3,))
    vo = _contact(sheet, contact)
    if not p[2] > 0.0:
        raise InvalidInputError("object_position", f"object height {p[2]:.6g} is not "
                                "above the ground (z_o must be > 0)")
    d = z - p[2]
    lengths = np.linalg.norm(sheet.vertices - vo, axis=1)
    s = sheet.size
    with np.errstate(invalid="ignore"):
        rho = np.sqrt(lengths ** 2 - d ** 2) / s
    return _Target(p, z, d, vo, lengths, (sheet.vertices - vo) / s, rho, s)


def contact_weights(sheet: Sheet, contact: ArrayLike | None = None) -> np.ndarray:
    """Maximum-entropy weights of a contact point: the unique :math:`w > 0`, :math:`\\sum
    w_i = 1`, :math:`\\sum w_i \\mathbf{v}_i = \\mathbf{v}_o` maximising :math:`-\\sum w_i
    \\log w_i` (barycentric coordinates when N = 3).

    Parameters
    ----------
    sheet : Sheet
    contact : array_like, shape (2,), optional
        :math:`\\mathbf{v}_o`, strictly inside the sheet; default the area centroid.

    Returns
    -------
    ndarray, shape (N,)

    Raises
    ------
    InvalidInputError
        The contact point is not strictly inside the sheet.

    Examples
    --------
    >>> from taut.sheet import Sheet, contact_weights
    >>> contact_weights(Sheet([[0, 0], [2, 0], [0, 2]]), [0.5, 0.5]).round(6)
    array([0.5 , 0.25, 0.25])
    """
    sheet = as_sheet(sheet)
    return maxent_weights(sheet.vertices, _contact(sheet, contact), sheet.size)


def formation_from_angles(team: SheetTeam, object_position: ArrayLike, angles: ArrayLike, *,
                          contact: ArrayLike | None = None) -> np.ndarray:
    """Robot positions from the cable angles (planning paper eq. 10).

    :math:`\\mathbf{r}_i = \\mathbf{r}_o + \\sqrt{l_i^2 - d^2}\\,(\\cos\\theta_i, \\sin\\theta_i)`
    with :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|`, :math:`d = z_r - z_o`: every cable
    taut with the object at ``object_position``.

    Parameters
    ----------
    team : SheetTeam
        The sheet and the holding height :math:`z_r`.
    object_position : array_like, shape (3,)
        Target :math:`(x_o, y_o, z_o)`, same length unit as the sheet.
    angles : array_like, shape (..., N)
        :math:`\\theta_i` in radians (any leading batch axes).
    contact : array_like, shape (2,), optional
        :math:`\\mathbf{v}_o` (default: the sheet's area centroid).

    Returns
    -------
    ndarray, shape (..., N, 2)

    Raises
    ------
    InvalidInputError
        Object not above the ground or not below some cable's full length (no all-taut
        placement), contact outside the sheet, bad angles.
    """
    team = require_team(team)
    return _formation(_target(team, object_position, contact), angles, team.n)


def _formation(t: _Target, angles: ArrayLike, n: int) -> np.ndarray:
    """:func:`formation_from_angles` of a validated target of an ``n``-robot team."""
    cert = depth_certificate(t.d, t.lengths, t.z)
    if cert is not None:
        raise InvalidInputError("object_position", cert.message)
    th = as_array(angles, "angles")
    if th.ndim < 1 or th.shape[-1] != n:
        raise InvalidInputError("angles", f"last axis must have length {n} (one angle "
                                "per robot)")
    rho = t.rho * t.scale
    return t.p[:2] + rho[:, None] * np.stack([np.cos(th), np.sin(th)], axis=-1)


def _least_squares_weights(V: np.ndarray, vo: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """Weights (..., N) solving (sum 1, contact, horizontal balance) in least squares."""
    N = len(V)
    E = np.concatenate([np.broadcast_to(np.ones(N), rel.shape[:-1])[..., None, :],
                        np.broadcast_to((V - vo).T, rel.shape[:-2] + (2, N)),
                        np.swapaxes(rel, -1, -2)], axis=-2)       # (..., 5, N)
    rhs = np.zeros(E.shape[:-1])
    rhs[..., 0] = 1.0
    return np.asarray((np.linalg.pinv(E) @ rhs[..., None])[..., 0])


def ik_constraints(team: SheetTeam, object_position: ArrayLike, angles: ArrayLike,
                   weights: ArrayLike | None = None, *, contact: ArrayLike | None = None
                   ) -> IKConstraints:
    """Evaluate the all-taut stable-equilibrium conditions for given angles (eq. 10).

    Parameters
    ----------
    angles : array_like, shape (..., N)
        :math:`\\theta_i`, radians.
    weights : array_like, shape (..., N), optional
        Load shares; default: the least-squares solution of the five linear conditions
        (sum 1, contact, horizontal balance), which is exact whenever the angles admit one.
    Other parameters as in :func:`formation_from_angles`.

    Returns
    -------
    IKConstraints
    """
    team = require_team(team)
    t = _target(team, object_position, contact)
    R = _formation(t, angles, team.n)
    V, N = team.sheet.vertices, team.n
    rel = R - t.p[:2]                                     # (..., N, 2)
    if weights is None:
        w = _least_squares_weights(V, t.vo, rel)
    else:
        w = check_range(weights, "weights", 1e6, "(load shares, in [0, 1] at a solution)")
        if w.ndim == 0 or w.shape[-1] != N:
            raise InvalidInputError("weights", f"last axis must have length {N}")
        w = np.broadcast_to(w, R.shape[:-1])
    balance = np.einsum("...n,...nk->...k", w, rel)
    cres = np.concatenate([w.sum(axis=-1, keepdims=True) - 1.0, w @ V - t.vo], axis=-1)
    iu, ju = np.triu_indices(N, 1)
    spacing = (np.linalg.norm(V[iu] - V[ju], axis=1)
               - np.linalg.norm(R[..., iu, :] - R[..., ju, :], axis=-1))
    curv = curvature(rel / t.scale, t.V)
    return IKConstraints(R, w, balance, cres, spacing, w.min(axis=-1), curv)


# --------------------------------------------------------------------------- IK stages

def _verified(team: SheetTeam, t: _Target, R: np.ndarray) -> bool:
    """Forward kinematics of the world formation ``R`` (N, 2) has a stable equilibrium
    with every cable taut at the target (within VERIFY_RTOL of the sheet size).

    The one place IK calls forward kinematics: the team's cached FK solver (the engine
    behind :func:`~taut.sheet.forward_kinematics`)."""
    sheet = team.sheet
    try:
        fk = cached_solver(team, "fast").solve(R)
    except InvalidInputError:                # pragma: no cover - rounding at the limit
        return False
    tol = VERIFY_RTOL * sheet.size
    return any(e.stable and len(e.taut) == sheet.n
               and float(np.linalg.norm(e.object - t.p)) <= tol
               and float(np.linalg.norm(e.contact - t.vo)) <= tol for e in fk.equilibria)


def _preferred_directions(t: _Target, heading: float, ref_n: np.ndarray | None
                          ) -> np.ndarray:
    """phi (N,): sheet directions turned by ``heading``, or towards the reference robots."""
    sheet_dir = np.arctan2(t.V[:, 1], t.V[:, 0])
    if ref_n is None:
        return np.asarray(sheet_dir + heading)
    far = np.linalg.norm(ref_n, axis=1) > REFERENCE_MIN_RADIUS
    return np.asarray(np.where(far, np.arctan2(ref_n[:, 1], ref_n[:, 0]), sheet_dir))


def _motion(rho: np.ndarray, th: np.ndarray, ref_n: np.ndarray) -> float:
    return float(np.sum((rho[:, None] * np.column_stack([np.cos(th), np.sin(th)])
                         - ref_n) ** 2))


def _construct(t: _Target, w: np.ndarray, phi: np.ndarray, ref_n: np.ndarray | None
               ) -> tuple[Candidate | None, np.ndarray | None, int]:
    """Steps 2-3 of the module docstring. Returns the candidate (or None), the closure
    directions (or None) and the number of optimiser runs."""
    V, rho = t.V, t.rho
    a = w * rho
    best = closure = None
    pvec = np.column_stack([np.cos(phi), np.sin(phi)])
    u = closure_directions(a, pvec) if a.max() < a.sum() - a.max() else None
    if u is not None:
        th = np.arctan2(u[:, 1], u[:, 0])
        if check_solution(V, rho, w, th)[0]:
            closure = Candidate(th, w, "closure")
            best = closure if ref_n is None else None
    runs = 0
    if best is None:
        th0 = np.arctan2(u[:, 1], u[:, 0]) if u is not None else phi.copy()
        starts = [th0]
        if len(rho) == 3 and u is not None:              # the mirror-image closure triangle
            starts.append(2 * np.mean(phi) - th0)
        for th_start in starts:
            runs += 1
            out = joint_optimise(V, rho, phi, w, th_start, ref_n, len(rho) <= 4)
            if out is not None and check_solution(V, rho, out[1], out[0])[0]:
                best = Candidate(out[0], out[1], "optimised")
                break
    if ref_n is not None and closure is not None:
        if best is None or _motion(rho, closure.angles, ref_n) < _motion(rho, best.angles,
                                                                         ref_n):
            best = closure
    return best, u, runs


def _certify(t: _Target, w: np.ndarray) -> IKCertificate | None:
    """Step 4's proofs: the exact triangle test (N = 3) or the LP relaxation."""
    if not np.all(np.isfinite(t.rho)):               # pragma: no cover - depth proof first
        return None
    return triangle_certificate(t.V, t.rho, w) or closure_lp_certificate(t.V, t.rho)


def _unmet(team: SheetTeam, t: _Target, c: Candidate, limits: tuple[float, float]
           ) -> tuple[tuple[str, str], ...]:
    """The conditions candidate ``c`` does not meet, as (name, one-line reason) pairs:
    ``"sheet_margin"`` and ``"robustness"`` (empty: both met)."""
    margin_n, error = limits
    _, R, spacing, _, _ = check_solution(t.V, t.rho, c.weights, c.angles)
    out = []
    if spacing < margin_n * (1.0 - MARGIN_SLACK):
        out.append(("sheet_margin", f"sheet_margin {margin_n * t.scale:.4g} not met: the "
                    f"closest robot pair is {max(spacing, 0.0) * t.scale:.4g} inside its "
                    "sheet distance"))
    if error > 0 and not _robust(team, t, t.p[:2] + t.scale * R, error):
        out.append(("robustness", f"not robust: with the robots off by {error:.4g} the "
                    f"object is not held (no stable state within {ROBUST_REACH:g} x that "
                    "of the target)"))
    return tuple(out)


def _robust(team: SheetTeam, t: _Target, R: np.ndarray, error: float) -> bool:
    """The robustness admission: in ``ROBUST_DRAWS`` seeded draws, each robot of ``R``
    displaced by ``error`` in a random direction, the sheet is spanned and forward
    kinematics has a stable state within ``ROBUST_REACH * error`` of the target."""
    rng = np.random.default_rng(ROBUST_SEED)
    solver = cached_solver(team, "fast")
    for _ in range(ROBUST_DRAWS):
        a = rng.uniform(-np.pi, np.pi, len(R))
        P = R + error * np.column_stack([np.cos(a), np.sin(a)])
        if not feasible_formations(team.sheet, P[None])[0]:
            return False
        if not any(float(np.linalg.norm(e.object - t.p)) <= ROBUST_REACH * error
                   for e in solver.solve(P).stable):
            return False
    return True


def _admit(team: SheetTeam, t: _Target, c: Candidate, phi: np.ndarray,
           ref_n: np.ndarray | None, limits: tuple[float, float]
           ) -> tuple[Candidate, tuple[tuple[str, str], ...]]:
    """A verified candidate that keeps the sheet margin and passes the robustness
    admission: ``c`` itself, or the joint optimisation from it with the margin (then twice
    the margin) as a constraint; failing both, ``c`` and the conditions it does not meet."""
    why = _unmet(team, t, c, limits)
    if not why:
        return c, why
    margin_n = limits[0]
    for m in (margin_n, 2.0 * margin_n):
        out = joint_optimise(t.V, t.rho, phi, c.weights, c.angles, ref_n, len(t.rho) <= 4,
                             m * (1.0 + MARGIN_SLACK))
        if out is None:
            continue
        ok, R, *_ = check_solution(t.V, t.rho, out[1], out[0])
        if not ok or not _verified(team, t, t.p[:2] + t.scale * R):
            continue
        better = Candidate(out[0], out[1], "optimised")
        if not _unmet(team, t, better, limits):
            return better, ()
    return c, why


def _success(sheet: Sheet, t: _Target, c: Candidate, unmet: tuple[tuple[str, str], ...],
             mass: float | None, runs: int) -> IKResult:
    _, R, spacing, curv, _ = check_solution(t.V, t.rho, c.weights, c.angles)
    formation = t.p[:2] + R * t.scale
    formation.setflags(write=False)
    tensions = None if mass is None else c.weights * mass * GRAVITY * t.lengths / t.d
    msg = f"all {sheet.n} cables taut, stable ({c.how}), verified by forward kinematics"
    if unmet:
        msg += "; but " + "; ".join(why for _, why in unmet)
    return IKResult(formation, t.p, t.vo, np.angle(np.exp(1j * c.angles)), c.weights,
                    tensions, t.lengths, t.rho * t.scale, curv, max(spacing, 0.0) * t.scale,
                    c.how, True, "ok", msg, None, runs, tuple(name for name, _ in unmet))


def _failure(sheet: Sheet, t: _Target, status: str, message: str,
             cert: IKCertificate | None, runs: int) -> IKResult:
    nan = np.full(sheet.n, np.nan)
    formation = np.full((sheet.n, 2), np.nan)
    formation.setflags(write=False)
    return IKResult(formation, t.p, t.vo, nan, nan.copy(), None, t.lengths,
                    t.rho * t.scale, float("nan"), float("nan"), "none", False, status,
                    message, cert, runs)


def inverse_kinematics(team: SheetTeam, object_position: ArrayLike, *,
                       contact: ArrayLike | None = None, heading: float = 0.0,
                       reference: ArrayLike | None = None, budget: int = DEFAULT_BUDGET,
                       seed: int = 0, branch_boxes: int = DEFAULT_BRANCH_BOXES,
                       sheet_margin: float | None = None,
                       position_error: float | None = None) -> IKResult:
    """Robot formation that holds the object stably at ``object_position`` with every
    virtual cable taut (planning paper eq. 10; docs/sheet_kinematics.md §6).

    Parameters
    ----------
    team : SheetTeam
        The sheet, the holding height :math:`z_r` and, optionally, the object mass (kg)
        for the tensions (N).
    object_position : array_like, shape (3,)
        Target :math:`\\mathbf{p}_o = (x_o, y_o, z_o)`, :math:`z_o > 0`, same length unit
        as the sheet.
    contact : array_like, shape (2,), optional
        Where the object sits on the sheet, :math:`\\mathbf{v}_o` (sheet frame, same length
        unit as the sheet), strictly inside the sheet. Default: the sheet's area centroid.
    heading : float
        Rotation (radians, counter-clockwise) of the formation about the vertical through
        the object; at 0 cable ``i`` points roughly along :math:`\\mathbf{v}_i - \\mathbf{v}_o`.
        Ignored when ``reference`` is given.
    reference : array_like, shape (N, 2), optional
        A formation to stay close to (e.g. the current one): the solution then minimises
        :math:`\\sum|\\mathbf{r}_i - \\mathbf{r}^{ref}_i|^2`.
    budget : int
        Multi-start searches (step 4) before giving up with ``budget_exhausted``.
    seed : int
        Seed of the multi-start search (answers are deterministic for a given seed).
    branch_boxes : int
        Boxes of cable angles (one LP each) the branch-and-bound unreachability proof may
        examine (step 4b) before IK gives up with ``budget_exhausted``; 0 skips the proof.
    sheet_margin : float, optional
        Every robot pair of the answer stays at least this far inside its sheet distance
        (same length unit as the sheet; >= 0). Default: 1% of the sheet size
        (``IK_MARGIN_RTOL``; the planner's 10 mm on a 1 m sheet). Applies in every mode
        (``heading``, ``reference``, the search).
    position_error : float, optional
        Robustness admission (as the planner's): with every robot off by this much (same
        unit; ``ROBUST_DRAWS`` seeded draws), the object must stay held -- a stable state
        within ``ROBUST_REACH`` times this of the target. Default: half of
        ``sheet_margin`` (the planner's 5 mm with its 10 mm margin); 0 skips the check.

    Returns
    -------
    IKResult
        ``success`` with a formation verified by forward kinematics; it keeps
        ``sheet_margin`` and passes the robustness admission whenever some formation of
        the search does (a joint optimisation with the margin as a constraint is tried
        first). Where none does (e.g. a target whose every formation has a pair at its
        limit), the verified formation is still returned and ``unmet`` names the
        conditions it does not meet (``"sheet_margin"``, ``"robustness"``), the message
        says why. An unreachable target is not an error: the
        result has status ``"unreachable"`` with a ``certificate`` (a checkable proof),
        or ``"budget_exhausted"`` when neither a formation nor a proof was found; no
        exception is raised for it.

    Raises
    ------
    InvalidInputError
        Bad shapes or values, object not above the ground, contact not strictly inside
        the sheet, a team of more than :data:`taut._validate.MAX_IK_ROBOTS` robots.

    Examples
    --------
    >>> from taut.sheet import Sheet, SheetTeam, inverse_kinematics
    >>> square = Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]])
    >>> r = inverse_kinematics(SheetTeam(square, 1.0), [0.3, -0.2, 0.4])
    >>> r.success, r.status, r.weights.round(3).tolist()
    (True, 'ok', [0.25, 0.25, 0.25, 0.25])
    >>> far = inverse_kinematics(SheetTeam(square, 2.0), [0, 0, 0.05])   # deeper than the cables
    >>> far.status, far.certificate.kind
    ('unreachable', 'depth')
    """
    team = require_team(team)
    sheet = team.sheet
    if sheet.n > MAX_IK_ROBOTS:
        raise InvalidInputError("sheet", f"{sheet.n} robots; inverse kinematics takes at "
                                f"most {MAX_IK_ROBOTS} (its search grows as N^3 a step)")
    t = _target(team, object_position, contact)
    heading = as_finite_scalar(heading, "heading")
    budget = int(as_nonnegative(budget, "budget"))
    branch_boxes = int(as_nonnegative(branch_boxes, "branch_boxes"))
    margin = (IK_MARGIN_RTOL * sheet.size if sheet_margin is None
              else as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_LENGTH, "sheet units",
                              positive=False))
    error = (0.5 * margin if position_error is None
             else as_bounded(position_error, "position_error", MAX_SHEET_LENGTH,
                             "sheet units", positive=False))
    ref_n = None
    if reference is not None:
        ref_n = (as_array(reference, "reference", shape=(sheet.n, 2)) - t.p[:2]) / t.scale
    cert = (depth_certificate(t.d, t.lengths, t.z)
            or radial_certificate(t.V, t.rho, t.scale))
    if cert is not None:
        return _failure(sheet, t, "unreachable", cert.message, cert, 0)
    return _search(team, t, heading, ref_n, (budget, branch_boxes), seed,
                   (margin / t.scale, error))


def _search(team: SheetTeam, t: _Target, heading: float, ref_n: np.ndarray | None,
            budgets: tuple[int, int], seed: int, limits: tuple[float, float]) -> IKResult:
    """Steps 1-4 of the module docstring on a target with real reaches; every answer then
    passes :func:`_admit` (``limits``: the normalised sheet margin and the position error
    in the sheet's unit)."""
    sheet, mass = team.sheet, team.mass
    w = maxent_weights(sheet.vertices, t.vo, t.scale)
    phi = _preferred_directions(t, heading, ref_n)
    best, _, runs = _construct(t, w, phi, ref_n)
    if best is not None and _verified(team, t, t.p[:2] + t.scale * (
            t.rho[:, None] * np.column_stack([np.cos(best.angles), np.sin(best.angles)]))):
        return _success(sheet, t, *_admit(team, t, best, phi, ref_n, limits), mass, runs)
    cert = _certify(t, w)
    if cert is not None:
        return _failure(sheet, t, "unreachable", "no stable all-taut formation exists for "
                        f"this target and contact: {cert.message}", cert, runs)

    def accept(th: np.ndarray, wt: np.ndarray) -> bool:
        ok, R, *_ = check_solution(t.V, t.rho, wt, th)
        return ok and _verified(team, t, t.p[:2] + t.scale * R)

    budget, boxes = budgets
    early = min(budget, EARLY_SEARCHES)
    cert = closure_branch_certificate(t.V, t.rho, min(boxes, EARLY_BRANCH_BOXES))
    found, tried = (None, 0) if cert is not None else multistart_search(
        t.V, t.rho, w, phi, accept, budget=early, seed=seed)
    if found is None:
        if cert is None and boxes > EARLY_BRANCH_BOXES:
            cert = closure_branch_certificate(t.V, t.rho, boxes)
        if cert is not None:
            return _failure(sheet, t, "unreachable", "no stable all-taut formation exists "
                            f"for this target and contact: {cert.message}", cert,
                            runs + tried)
        found, more = multistart_search(t.V, t.rho, w, phi, accept, budget=budget - early,
                                        seed=seed + 1)
        tried += more
    if found is not None:
        return _success(sheet, t, *_admit(team, t, found, phi, ref_n, limits), mass,
                        runs + tried)
    return _failure(sheet, t, "budget_exhausted", "no stable all-taut formation found and "
                    f"no proof that none exists: closed-form closure, {runs} joint "
                    f"optimisation(s), {tried} multi-start feasibility search(es), the "
                    "LP relaxation of the closing conditions (feasible) and the "
                    f"branch-and-bound proof ({boxes} angle boxes) were tried",
                    None, runs + tried)
