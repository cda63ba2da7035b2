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
(eqs. 11-15); here they are fixed by the equilibrium conditions (DESIGN.md Sec. 3-5):

* weights :math:`w_i > 0`, :math:`\\sum w_i = 1`, :math:`\\sum w_i \\mathbf{v}_i = \\mathbf{v}_o`
  (the contact point fixes them for N = 3; a family of dimension N - 3 otherwise);
* horizontal balance :math:`\\sum w_i (\\mathbf{r}_i - \\mathbf{r}_o) = \\sum a_i \\mathbf{u}_i = 0`
  with :math:`a_i = w_i \\rho_i` (proportional to the horizontal tension of cable ``i``);
* stability: the reduced Hessian of :math:`|\\mathbf{r}_o|^2 - |\\mathbf{v}_o|^2` on the
  null space of the rows :math:`(\\mathbf{r}_i - \\mathbf{r}_1, -(\\mathbf{v}_i - \\mathbf{v}_1))`
  positive definite (automatic when those rows have rank 4, i.e. generic N >= 5);
* the formation is feasible: :math:`|\\mathbf{r}_i - \\mathbf{r}_j| \\le |\\mathbf{v}_i -
  \\mathbf{v}_j|`. This is *not* automatic: two cables whose sheet directions are close can
  be pulled apart horizontally farther than the sheet allows.

Choice within the family (the papers are silent; our documented objective):

1. weights: the maximum-entropy weights of the contact point (the unique :math:`w > 0`
   maximising :math:`-\\sum w_i \\log w_i` with the contact constraints; barycentric for
   N = 3, smooth in :math:`\\mathbf{v}_o`);
2. angles: each cable's preferred direction is its sheet direction
   :math:`\\mathbf{v}_i - \\mathbf{v}_o` turned by ``heading`` (so at heading 0 the formation
   looks like the flat sheet shrunk towards the contact point), and the angles maximise the
   tension-weighted alignment :math:`\\sum a_i \\cos(\\theta_i - \\phi_i)` subject to the
   horizontal balance. Its dual is a weighted Fermat-Weber problem: with ``m`` the weighted
   geometric median of the unit vectors :math:`\\mathbf{p}_i = (\\cos\\phi_i, \\sin\\phi_i)`
   (weights :math:`a_i`), :math:`\\mathbf{u}_i = (\\mathbf{p}_i - m)/|\\mathbf{p}_i - m|`;
3. if that formation is infeasible or unstable, weights and angles are optimised jointly
   (SLSQP) for the same alignment with every condition as a constraint.

With ``reference`` (e.g. the team's current formation), step 3 instead minimises the total
squared robot motion :math:`\\sum |\\mathbf{r}_i - \\mathbf{r}^{ref}_i|^2`, starting from
preferred directions towards the reference robots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from .._validate import as_array, as_finite_scalar
from ..errors import InvalidInputError, UnreachableTargetError
from .fk import _check_mass, _check_sheet
from .model import GEOMETRY_RTOL, Sheet, check_hold_height
from .results import GRAVITY

__all__ = ["IKResult", "IKConstraints", "inverse_kinematics", "formation_from_angles",
           "ik_constraints", "contact_weights"]

#: Smallest weight (share of the load) an IK solution may give a cable.
MIN_WEIGHT = 1e-6
#: Smallest reduced-Hessian eigenvalue (dimensionless) of an IK solution.
MIN_CURVATURE = 1e-6
#: Robots must be at least this much (times the sheet size) closer than their vertices.
SPACING_MARGIN = 1e-8

_J = np.array([1.0, 1.0, -1.0, -1.0])


@dataclass(frozen=True, eq=False)
class IKResult:
    """A formation that holds the object stably at the target with every cable taut.

    Attributes
    ----------
    formation : ndarray, shape (N, 2)
        Robot positions :math:`\\mathbf{r}_i` (world frame, length unit of the sheet).
    object : ndarray, shape (3,)
        The target :math:`\\mathbf{p}_o = (x_o, y_o, z_o)`.
    contact : ndarray, shape (2,)
        Contact point :math:`\\mathbf{v}_o` in the sheet frame.
    angles : ndarray, shape (N,)
        :math:`\\theta_i` of eq. (10), radians, in (-pi, pi].
    weights : ndarray, shape (N,)
        Vertical load shares :math:`w_i > 0` (sum 1).
    tensions : ndarray, shape (N,), or None
        :math:`F_i = w_i m g l_i / d` in N when a mass was given.
    cable_lengths : ndarray, shape (N,)
        :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|`.
    reach : ndarray, shape (N,)
        Horizontal robot-object distances :math:`\\rho_i = \\sqrt{l_i^2 - d^2}`.
    curvature : float
        Smallest eigenvalue of the reduced Hessian (``inf`` when the cables fix the state).
    spacing : float
        Smallest :math:`(|\\mathbf{v}_i - \\mathbf{v}_j| - |\\mathbf{r}_i - \\mathbf{r}_j|)` over
        robot pairs (>= 0: a feasible formation).
    construction : {"closure", "optimised"}
        Whether the closed-form construction (steps 1-2 of the module docstring) sufficed
        or the joint optimisation (step 3) was needed.
    """

    formation: np.ndarray
    object: np.ndarray
    contact: np.ndarray
    angles: np.ndarray
    weights: np.ndarray
    tensions: np.ndarray | None
    cable_lengths: np.ndarray
    reach: np.ndarray
    curvature: float
    spacing: float
    construction: str

    @property
    def min_weight(self) -> float:
        """Smallest cable weight."""
        return float(self.weights.min())


@dataclass(frozen=True, eq=False)
class IKConstraints:
    """Conditions of an all-taut stable rest state for given angles (and weights).

    Every field is zero/non-negative at a valid IK solution; optimisers over the angles
    :math:`\\theta_i` of eq. (10) can use them as constraints.

    Attributes
    ----------
    formation : ndarray, shape (..., N, 2)
        Robots from eq. (10).
    weights : ndarray, shape (..., N)
        The weights used (given, or the least-squares weights satisfying the contact and
        balance equations best).
    balance : ndarray, shape (..., 2)
        Horizontal balance :math:`\\sum w_i(\\mathbf{r}_i - \\mathbf{r}_o)` (must be 0), in
        length units.
    contact_residual : ndarray, shape (..., 3)
        :math:`(\\sum w_i - 1, \\sum w_i \\mathbf{v}_i - \\mathbf{v}_o)` (must be 0).
    spacing : ndarray, shape (..., N(N-1)/2)
        :math:`|\\mathbf{v}_i - \\mathbf{v}_j| - |\\mathbf{r}_i - \\mathbf{r}_j|` for pairs
        ``i < j`` in ``numpy.triu_indices`` order (must be >= 0).
    min_weight : ndarray, shape (...)
        (must be > 0).
    curvature : ndarray, shape (...)
        Smallest reduced-Hessian eigenvalue (must be > 0; ``inf`` when fixed).
    """

    formation: np.ndarray
    weights: np.ndarray
    balance: np.ndarray
    contact_residual: np.ndarray
    spacing: np.ndarray
    min_weight: np.ndarray
    curvature: np.ndarray

    @property
    def feasible(self) -> np.ndarray:
        """Bool (...): every condition holds (tolerances relative to the balance scale)."""
        scale = np.max(np.abs(self.formation - self.formation.mean(axis=-2, keepdims=True)),
                       axis=(-2, -1))
        return ((np.linalg.norm(self.balance, axis=-1) <= 1e-9 * np.maximum(scale, 1e-300))
                & (np.abs(self.contact_residual).max(axis=-1) <= 1e-9 * np.maximum(scale, 1))
                & (self.spacing.min(axis=-1) >= -GEOMETRY_RTOL * np.maximum(scale, 1e-300))
                & (self.min_weight > 0) & (self.curvature > 0))


# --------------------------------------------------------------------------- helpers

def _target(sheet: Sheet, object_position: object, hold_height: float, contact: object
            ) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """Validated target: object (3,), depth d, contact (2,), cable lengths (N,)."""
    p = as_array(object_position, "object_position", shape=(3,))
    z = check_hold_height(hold_height)
    if contact is None:
        vo = sheet.centroid
    else:
        vo = as_array(contact, "contact", shape=(2,))
    d = z - p[2]
    if not p[2] > 0.0:
        raise UnreachableTargetError("object_position", f"object height {p[2]:.6g} is not "
                                     "above the ground (z_o must be > 0)")
    if not d > 0.0:
        raise UnreachableTargetError("object_position", f"object height {p[2]:.6g} is not "
                                     f"below the holding height {z:.6g}")
    inner = sheet.contains(vo, tol=-1e-9)
    if not bool(inner):
        raise UnreachableTargetError("contact", f"contact point ({vo[0]:.6g}, {vo[1]:.6g}) "
                                     "is not strictly inside the sheet")
    lengths = np.linalg.norm(sheet.vertices - vo, axis=1)
    short = lengths <= d * (1 + 1e-12)
    if np.any(short):
        i = int(np.argmin(lengths))
        raise UnreachableTargetError(
            "object_position", f"object too deep: depth {d:.6g} below the robots but the "
            f"cable to vertex {i + 1} is only {lengths[i]:.6g} long (raise the object or "
            "move the contact point away from that vertex)")
    return p, d, vo, lengths


def contact_weights(sheet: Sheet, contact: object | None = None) -> np.ndarray:
    """Maximum-entropy weights of a contact point: the unique :math:`w > 0`, :math:`\\sum
    w_i = 1`, :math:`\\sum w_i \\mathbf{v}_i = \\mathbf{v}_o` maximising :math:`-\\sum w_i
    \\log w_i` (barycentric coordinates when N = 3).

    Solved by Newton's method on the 2-D dual: :math:`w_i \\propto \\exp(\\lambda \\cdot
    (\\mathbf{v}_i - \\mathbf{v}_o))`.

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
    UnreachableTargetError
        The contact point is not strictly inside the sheet.
    """
    sheet = _check_sheet(sheet)
    vo = sheet.centroid if contact is None else as_array(contact, "contact", shape=(2,))
    if not bool(sheet.contains(vo, tol=-1e-9)):
        raise UnreachableTargetError("contact", f"contact point ({vo[0]:.6g}, {vo[1]:.6g}) "
                                     "is not strictly inside the sheet")
    return _maxent(sheet.vertices, vo, sheet.size)


def _maxent(V: np.ndarray, vo: np.ndarray, scale: float) -> np.ndarray:
    E = (V - vo) / scale
    lam = np.zeros(2)

    def dual(lam: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        s = E @ lam
        top = s.max()
        e = np.exp(s - top)
        return float(top + np.log(e.sum())), e / e.sum(), s

    f, w, _ = dual(lam)
    for _ in range(200):
        g = w @ E
        if np.linalg.norm(g) < 1e-15:
            break
        H = (E * w[:, None]).T @ E - np.outer(g, g)
        try:
            step = -np.linalg.solve(H + 1e-300 * np.eye(2), g)
        except np.linalg.LinAlgError:
            step = -g
        t = 1.0
        while True:
            f_new, w_new, _ = dual(lam + t * step)
            if f_new <= f + 1e-4 * t * float(g @ step) or t < 1e-12:
                break
            t *= 0.5
        lam, f, w = lam + t * step, f_new, w_new
    return w


def _closure_directions(a: np.ndarray, p: np.ndarray) -> np.ndarray | None:
    """Unit vectors u_i maximising sum a_i u_i . p_i subject to sum a_i u_i = 0.

    ``u_i = (p_i - m)/|p_i - m|`` with ``m`` the ``a``-weighted geometric median of the
    ``p_i`` (damped Newton on the convex :math:`\\Phi(m) = \\sum a_i |p_i - m|`). Returns
    None when the median sits on one of the points (no balanced directions this way).
    """
    total = a.sum()
    m = (a[:, None] * p).sum(axis=0) / total

    def phi(m: np.ndarray) -> float:
        return float((a * np.linalg.norm(p - m, axis=1)).sum())

    f = phi(m)
    for _ in range(100):
        diff = p - m
        n = np.linalg.norm(diff, axis=1)
        if n.min() <= 1e-13:
            return None
        u = diff / n[:, None]
        g = -(a[:, None] * u).sum(axis=0)
        if np.linalg.norm(g) <= 1e-14 * total:
            return u
        H = np.einsum("i,ijk->jk", a / n, np.eye(2)[None] - u[:, :, None] * u[:, None, :])
        try:
            step = -np.linalg.solve(H, g)
        except np.linalg.LinAlgError:
            step = -g
        t = 1.0
        while True:
            trial = m + t * step
            f_new = phi(trial)
            if f_new <= f + 1e-4 * t * float(g @ step) or t < 1e-14:
                break
            t *= 0.5
        if t < 1e-14:
            break
        m, f = trial, f_new
    diff = p - m
    n = np.linalg.norm(diff, axis=1)
    if n.min() <= 1e-13:
        return None
    u = diff / n[:, None]
    return u if np.linalg.norm((a[:, None] * u).sum(axis=0)) <= 1e-10 * total else None


def _curvature(R: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Smallest eigenvalue of diag(1,1,-1,-1) on the null space of the rows
    (r_i - r_1, -(v_i - v_1)); R (..., N, 2) and V (N, 2) in normalised units.
    ``inf`` when the rows have rank 4."""
    lead = R.shape[:-2]
    N = R.shape[-2]
    Vb = np.broadcast_to(V, R.shape)
    A = np.concatenate([R, -Vb], axis=-1)                 # (..., N, 4)
    D = (A[..., 1:, :] - A[..., :1, :]).reshape(-1, N - 1, 4)
    _, sv, vt = np.linalg.svd(D, full_matrices=True)
    out = np.full(D.shape[0], np.inf)
    top = np.maximum(sv[:, 0], 1e-300)
    rank = np.sum(sv > 1e-9 * top[:, None], axis=1)
    for r in np.unique(rank):
        if r >= 4:
            continue
        sel = rank == r
        Z = vt[sel, r:, :]
        Hr = np.einsum("mik,k,mjk->mij", Z, _J, Z)
        out[sel] = np.linalg.eigvalsh(Hr)[:, 0]
    return out.reshape(lead)


def _wrap(theta: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * theta))


# --------------------------------------------------------------------------- public API

def formation_from_angles(sheet: Sheet, object_position: object, hold_height: float,
                          angles: object, *, contact: object | None = None) -> np.ndarray:
    """Robot positions from the cable angles (planning paper eq. 10).

    :math:`\\mathbf{r}_i = \\mathbf{r}_o + \\sqrt{l_i^2 - d^2}\\,(\\cos\\theta_i, \\sin\\theta_i)`
    with :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|`, :math:`d = z_r - z_o`: every cable
    taut with the object at ``object_position``.

    Parameters
    ----------
    sheet : Sheet
    object_position : array_like, shape (3,)
        Target :math:`(x_o, y_o, z_o)`.
    hold_height : float
        :math:`z_r`.
    angles : array_like, shape (..., N)
        :math:`\\theta_i` in radians (any leading batch axes).
    contact : array_like, shape (2,), optional
        :math:`\\mathbf{v}_o` (default: the sheet's area centroid).

    Returns
    -------
    ndarray, shape (..., N, 2)

    Raises
    ------
    UnreachableTargetError
        Object not between ground and robots, contact outside the sheet, object deeper
        than some cable is long.
    """
    sheet = _check_sheet(sheet)
    p, d, _, lengths = _target(sheet, object_position, hold_height, contact)
    th = as_array(angles, "angles")
    if th.ndim < 1 or th.shape[-1] != sheet.n:
        raise InvalidInputError("angles", f"last axis must have length {sheet.n} (one angle "
                                "per robot)")
    rho = np.sqrt(lengths ** 2 - d ** 2)
    return p[:2] + rho[:, None] * np.stack([np.cos(th), np.sin(th)], axis=-1)


def ik_constraints(sheet: Sheet, object_position: object, hold_height: float,
                   angles: object, weights: object | None = None, *,
                   contact: object | None = None) -> IKConstraints:
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
    sheet = _check_sheet(sheet)
    p, d, vo, lengths = _target(sheet, object_position, hold_height, contact)
    R = formation_from_angles(sheet, p, hold_height, angles, contact=vo)
    V = sheet.vertices
    N = sheet.n
    rel = R - p[:2]                                       # (..., N, 2)
    if weights is None:
        E = np.concatenate([np.broadcast_to(np.ones(N), R.shape[:-1])[..., None, :],
                            np.broadcast_to((V - vo).T, R.shape[:-2] + (2, N)),
                            np.swapaxes(rel, -1, -2)], axis=-2)       # (..., 5, N)
        rhs = np.zeros(E.shape[:-1])
        rhs[..., 0] = 1.0
        w = (np.linalg.pinv(E) @ rhs[..., None])[..., 0]
    else:
        w = as_array(weights, "weights")
        if w.shape[-1] != N:
            raise InvalidInputError("weights", f"last axis must have length {N}")
        w = np.broadcast_to(w, R.shape[:-1])
    balance = np.einsum("...n,...nk->...k", w, rel)
    cres = np.concatenate([w.sum(axis=-1, keepdims=True) - 1.0, w @ V - vo], axis=-1)
    iu, ju = np.triu_indices(N, 1)
    spacing = (np.linalg.norm(V[iu] - V[ju], axis=1)
               - np.linalg.norm(R[..., iu, :] - R[..., ju, :], axis=-1))
    s = sheet.size
    curv = _curvature((R - p[:2]) / s, (V - vo) / s)
    return IKConstraints(R, w, balance, cres, spacing, w.min(axis=-1), curv)


def _joint_optimise(V: np.ndarray, rho: np.ndarray, phi: np.ndarray, w0: np.ndarray,
                    th0: np.ndarray, ref: np.ndarray | None, need_curv: bool
                    ) -> tuple[np.ndarray, np.ndarray] | None:
    """SLSQP over (theta, w) in normalised units (object at the origin, contact at 0)."""
    N = len(rho)
    iu, ju = np.triu_indices(N, 1)
    vdist2 = np.sum((V[iu] - V[ju]) ** 2, axis=1) * (1 - 1e-7)

    def split(z):
        return z[:N], z[N:]

    def robots(th):
        return rho[:, None] * np.column_stack([np.cos(th), np.sin(th)])

    def d_robots(th):
        return rho[:, None] * np.column_stack([-np.sin(th), np.cos(th)])

    if ref is None:
        def obj(z):
            th, w = split(z)
            a = w * rho
            S, c = a.sum(), np.cos(th - phi)
            A = (a * c).sum()
            g = np.concatenate([a * np.sin(th - phi) / S, -(rho * c * S - A * rho) / S ** 2])
            return -A / S, g
    else:
        def obj(z):
            th, _ = split(z)
            diff = robots(th) - ref
            g_th = 2 * np.einsum("ik,ik->i", diff, d_robots(th))
            return float(np.sum(diff ** 2)), np.concatenate([g_th, np.zeros(N)])

    def eq(z):
        th, w = split(z)
        return np.concatenate([[w.sum() - 1.0], w @ V, (w[:, None] * robots(th)).sum(axis=0)])

    def eq_jac(z):
        th, w = split(z)
        J = np.zeros((5, 2 * N))
        J[0, N:] = 1.0
        J[1:3, N:] = V.T
        J[3:5, :N] = (w[:, None] * d_robots(th)).T
        J[3:5, N:] = robots(th).T
        return J

    def ineq(z):
        th, w = split(z)
        R = robots(th)
        out = [w - MIN_WEIGHT * 10, vdist2 - np.sum((R[iu] - R[ju]) ** 2, axis=1)]
        return np.concatenate(out)

    def ineq_jac(z):
        th, _ = split(z)
        R, dR = robots(th), d_robots(th)
        P = len(iu)
        J = np.zeros((N + P, 2 * N))
        J[:N, N:] = np.eye(N)
        diff = R[iu] - R[ju]
        rows = N + np.arange(P)
        J[rows, iu] = -2 * np.einsum("pk,pk->p", diff, dR[iu])
        J[rows, ju] = 2 * np.einsum("pk,pk->p", diff, dR[ju])
        return J

    cons = [{"type": "eq", "fun": eq, "jac": eq_jac},
            {"type": "ineq", "fun": ineq, "jac": ineq_jac}]
    if need_curv:
        cons.append({"type": "ineq",
                     "fun": lambda z: np.atleast_1d(np.minimum(
                         _curvature(robots(z[:N]), V), 1.0) - 10 * MIN_CURVATURE)})
    z0 = np.concatenate([th0, w0])
    try:
        res = minimize(obj, z0, jac=True, method="SLSQP", constraints=cons,
                       bounds=[(None, None)] * N + [(0.0, 1.0)] * N,
                       options={"maxiter": 300, "ftol": 1e-12})
    except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
        return None
    th, w = split(res.x)
    return _polish(V, rho, w, th)


def _polish(V: np.ndarray, rho: np.ndarray, w: np.ndarray, th: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray] | None:
    """Make the balance exact (to rounding): project w onto the contact constraints, then
    re-solve the angles for those weights by a few Newton steps on sum a_i u_i = 0."""
    N = len(rho)
    if not np.all(np.isfinite(w)) or not np.all(np.isfinite(th)):
        return None
    for _ in range(3):
        E = np.vstack([np.ones(N), V.T, (rho[:, None] * np.column_stack(
            [np.cos(th), np.sin(th)])).T])
        rhs = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
        w = w - np.linalg.pinv(E) @ (E @ w - rhs)
    return th, w


def _check_solution(V: np.ndarray, rho: np.ndarray, w: np.ndarray, th: np.ndarray):
    """Exact checks of a candidate (normalised units): ok, robots, spacing, curvature,
    balance residual."""
    R = rho[:, None] * np.column_stack([np.cos(th), np.sin(th)])
    N = len(rho)
    iu, ju = np.triu_indices(N, 1)
    spacing = np.linalg.norm(V[iu] - V[ju], axis=1) - np.linalg.norm(R[iu] - R[ju], axis=1)
    curv = float(_curvature(R, V))
    bal = np.linalg.norm((w[:, None] * R).sum(axis=0))
    cres = max(abs(w.sum() - 1.0), np.abs(w @ V).max())
    ok = (w.min() >= MIN_WEIGHT and spacing.min() >= SPACING_MARGIN and curv >= MIN_CURVATURE
          and bal <= 1e-11 and cres <= 1e-11)
    return ok, R, float(spacing.min()), curv, bal


def inverse_kinematics(sheet: Sheet, object_position: object, hold_height: float, *,
                       contact: object | None = None, heading: float = 0.0,
                       reference: object | None = None, mass: float | None = None
                       ) -> IKResult:
    """Robot formation that holds the object stably at ``object_position`` with every
    virtual cable taut (planning paper eq. 10; DESIGN.md Sec. 3-5).

    Parameters
    ----------
    sheet : Sheet
    object_position : array_like, shape (3,)
        Target :math:`\\mathbf{p}_o = (x_o, y_o, z_o)`, :math:`0 < z_o < z_r`.
    hold_height : float
        :math:`z_r` (> 0).
    contact : array_like, shape (2,), optional
        Where the object sits on the sheet, :math:`\\mathbf{v}_o` (sheet frame), strictly
        inside the sheet. Default: the sheet's area centroid (the point that keeps the
        cables balanced for symmetric sheets and is always interior).
    heading : float
        Rotation (radians, counter-clockwise) of the formation about the vertical through
        the object; at 0 cable ``i`` points roughly along :math:`\\mathbf{v}_i - \\mathbf{v}_o`.
        Ignored when ``reference`` is given.
    reference : array_like, shape (N, 2), optional
        A formation to stay close to (e.g. the current one): the solution then minimises
        :math:`\\sum|\\mathbf{r}_i - \\mathbf{r}^{ref}_i|^2`.
    mass : float, optional
        Object mass (kg) for the tensions.

    Returns
    -------
    IKResult

    Raises
    ------
    InvalidInputError
        Bad shapes or values.
    UnreachableTargetError
        Object not strictly between ground and holding height, contact not strictly
        inside the sheet, object deeper than the shortest cable, or no stable all-taut
        formation found (the message says which condition failed).
    """
    sheet = _check_sheet(sheet)
    mass = _check_mass(mass)
    p, d, vo, lengths = _target(sheet, object_position, hold_height, contact)
    heading = as_finite_scalar(heading, "heading")
    N, s = sheet.n, sheet.size
    ref = None
    if reference is not None:
        ref = as_array(reference, "reference", shape=(N, 2))
    V = (sheet.vertices - vo) / s                          # contact at the origin
    rho = np.sqrt(lengths ** 2 - d ** 2) / s
    _check_radial_spacing(V, rho, s)
    need_curv = N <= 4
    w = _maxent(sheet.vertices, vo, s)
    if ref is None:
        phi = np.arctan2(V[:, 1], V[:, 0]) + heading
        ref_n = None
    else:
        ref_n = (ref - p[:2]) / s
        far = np.linalg.norm(ref_n, axis=1) > 1e-9
        phi = np.where(far, np.arctan2(ref_n[:, 1], ref_n[:, 0]), np.arctan2(V[:, 1], V[:, 0]))
    pvec = np.column_stack([np.cos(phi), np.sin(phi)])
    a = w * rho
    best = closure = None
    u = _closure_directions(a, pvec) if a.max() < a.sum() - a.max() else None
    if u is not None:
        th = np.arctan2(u[:, 1], u[:, 0])
        ok, *_ = _check_solution(V, rho, w, th)
        if ok:
            closure = (th, w, "closure")
            best = closure if ref is None else None
    if best is None:
        th0 = np.arctan2(u[:, 1], u[:, 0]) if u is not None else phi.copy()
        starts = [th0]
        if N == 3 and u is not None:              # the mirror-image closure triangle
            starts.append(2 * np.mean(phi) - th0)
        for th_start in starts:
            out = _joint_optimise(V, rho, phi, w, th_start, ref_n, need_curv)
            if out is None:
                continue
            ok, *_ = _check_solution(V, rho, out[1], out[0])
            if ok:
                best = (out[0], out[1], "optimised")
                break
    if ref_n is not None and closure is not None:
        def motion(th: np.ndarray) -> float:
            return float(np.sum((rho[:, None] * np.column_stack(
                [np.cos(th), np.sin(th)]) - ref_n) ** 2))
        if best is None or motion(closure[0]) < motion(best[0]):
            best = closure
    if best is None:
        why = _diagnose(V, rho, w, a, u)
        raise UnreachableTargetError("object_position", f"no stable all-taut formation "
                                     f"found for this target and contact: {why}")
    th, w, how = best
    ok, R, spacing, curv, _ = _check_solution(V, rho, w, th)
    formation = p[:2] + R * s
    tensions = None if mass is None else w * mass * GRAVITY * lengths / d
    formation.setflags(write=False)
    return IKResult(formation, p, vo, _wrap(th), w, tensions, lengths, rho * s, curv,
                    spacing * s, how)


def _check_radial_spacing(V: np.ndarray, rho: np.ndarray, scale: float) -> None:
    """Exact necessary condition for any all-taut formation (planning paper eq. 10).

    Robot ``i`` must stand at horizontal distance ``rho_i`` from the object, whatever its
    angle; by the triangle inequality two robots are then at least ``|rho_i - rho_j|``
    apart, and the sheet allows at most ``|v_i - v_j|``. A pair violating this proves that
    no all-taut formation exists (no search needed). Lengths normalised by ``scale``.
    """
    D = np.linalg.norm(V[:, None, :] - V[None, :, :], axis=2)
    excess = np.abs(rho[:, None] - rho[None, :]) - D
    k = int(np.argmax(excess))
    i, j = divmod(k, len(rho))
    if excess.flat[k] > SPACING_MARGIN:
        i, j = min(i, j), max(i, j)
        raise UnreachableTargetError(
            "object_position", f"no all-taut formation exists for this target and contact: "
            f"robots {i + 1} and {j + 1} must stand {rho[i] * scale:.6g} and "
            f"{rho[j] * scale:.6g} from the object horizontally, at least "
            f"{abs(rho[i] - rho[j]) * scale:.6g} apart, but the sheet holds them at most "
            f"{D[i, j] * scale:.6g} apart")


def _diagnose(V, rho, w, a, u) -> str:
    if len(rho) == 3 and not a.max() < a.sum() - a.max():
        i = int(np.argmax(a))
        return (f"cable {i + 1} would pull sideways harder than the other two together "
                "(horizontal forces cannot balance)")
    if u is None:
        return "the horizontal cable forces cannot be balanced"
    ok, R, spacing, curv, _ = _check_solution(V, rho, w, np.arctan2(u[:, 1], u[:, 0]))
    if spacing < SPACING_MARGIN:
        return "the balanced robots would stand farther apart than the sheet allows"
    if curv < MIN_CURVATURE:
        return "the balanced state is not a stable minimum (the object would roll away)"
    return "the optimiser found no formation meeting every condition"
