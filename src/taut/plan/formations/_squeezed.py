"""Squeezed formations: the narrowest formation holding the object with some cables slack
(our extension of the planning paper's formation library).

The planning paper (J. Hu et al., "Multi-robot object transport motion planning with a
deformable sheet", RA-L 2022) plans with all-taut formations, measured by eqs. (1)-(4)
(size, :math:`h_{max}`, :math:`d_{min}`, :math:`D_{max}`). With every cable taut robot ``i``
stands on the circle of radius :math:`\\sqrt{l_i^2 - d^2}` about the object, so the
narrowest all-taut formation (``optimal_formation(kind="narrow")``) already holds the object
at the ground safety height. Letting some cables go slack squeezes the team further. The
quasi-static model of the FK paper (J. Hu et al., "Forward kinematics of object transport
by a multi-robot system with deformable sheet") decides the rest state: *stable* is a strict
local minimum of the object's height. We design the narrowest formation (width of the
robots' centres across its x axis, the extent eq. (1) bounds across a corridor) whose rest
state is stable and the *only* stable one (the planner carries the object rigidly with the
formation, so it must know where the object is), with the object at least
``height_safety + SQUEEZE_HEIGHT_MARGIN`` high and at least ``inset`` inside the convex
hull of the taut robots (our force-closure margin: forward kinematics calls a state on the
edge of that polygon, e.g. every robot on a line, stable, yet the least sideways push moves
the object off it), robots two radii apart and every pair ``sheet_margin`` inside its sheet
distance (eq. 15c).

Method. The object's depth below the hands is :math:`d^2 = \\max_x \\min_i g_i(x)`,
:math:`g_i = |\\mathbf{v}_o - \\mathbf{v}_i|^2 - |\\mathbf{r}_o - \\mathbf{r}_i|^2`,
:math:`x = (\\mathbf{r}_o, \\mathbf{v}_o)`. The :math:`g_i` share their quadratic part, so
the state with the cables ``K`` taut is one linear system (:func:`_pocket`); it is stable
iff its weights are positive and diag(1, 1, -1, -1) is positive definite on its face. For
each triple of taut cables SciPy's SLSQP minimises the width over the robot coordinates
with these requirements as smooth constraints; every other stable state forward kinematics
then finds gets a cut (one of its weights or its face's curvature below zero, or one of its
slack cables over length, whichever is nearest) for the next of at most ``ROUNDS`` solves.
Every iterate is accepted by forward kinematics alone (:func:`_accept`), never by the
program. Triples go in the order of how little the start violates their program; the
search stops at a formation at most ``width`` wide (then maximises its margins at that
width), or within ``SQUEEZE_WIDTH_TOL`` of the lower bound ``2 inset`` (a polygon holding a
disc of radius ``inset`` is at least that wide). Lengths in metres.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from ..._validate import MAX_SHEET_LENGTH, as_bounded, require_instance
from ...errors import InvalidInputError, TautError
from ...sheet import Equilibrium, FKSolver, formation_metrics
from .. import _tol
from .._tol import MAX_SHEET_MARGIN_M
from ._problem import MIN_DEPTH_FRACTION
from ._squeeze_robust import convex_hull, hull_inset, tolerates
from .optimal import Formation, _optimal_formation
from ..world import Team

__all__ = ["squeezed_formation"]

#: The start is squeezed to these fractions of its extent along y (x kept) before the search,
#: which takes it off the degenerate all-taut configurations (m/m). The search is local:
#: when the one from a start finds no formation narrow enough, the next start is tried
#: (suite-2024 scenario 3: from 0.8 the rounding of one CPU led to a 0.72 m formation
#: against the 0.69 m passage, from 0.85 to 0.25 m).
START_SQUEEZES = (0.8, 0.85)
#: Solves per triple of taut cables (each after the first adds cuts).
ROUNDS = 3
#: SLSQP iterations per solve.
MAX_ITER = 40
#: Robot coordinates stay within this many sheet sizes of the origin (keeps SLSQP from
#: diverging on triples that hold no formation).
BOX = 3.0
#: Most triples of taut cables tried, likeliest first (of C(8, 3) = 56 for eight robots; on
#: the seed-2024 suite the narrowest was among the first 16 but for a few millimetres).
MAX_TRIPLES = 16
#: Weight of the margin maximised at a fixed width (normalised): SLSQP's first step moves
#: it by about this much, within reach of the linearised constraints.
MARGIN_SCALE = 0.03

Cut = tuple[tuple[int, ...], str, int]


@dataclass(frozen=True)
class _Limits:
    """The requirements, normalised by the sheet size ``s`` (``metres``: the same in m)."""

    V: np.ndarray           # sheet vertices (N, 2)
    s: float                # sheet size, m
    d_hi: float             # deepest object below the hands (height safety + margin up)
    d_lo: float             # shallowest (MIN_DEPTH_FRACTION of the hold height)
    inset: float            # least inset of the object in its taut robots' hull
    sep: float              # least robot distance
    dmax: np.ndarray        # largest distance of each pair (iu, ju)
    slack: float            # least slack of a slack cable
    metres: dict            # z_min (lowest object height), inset, sep, dmax in m

    @property
    def n(self) -> int:
        return len(self.V)

    @property
    def pairs(self) -> tuple[np.ndarray, np.ndarray]:
        return np.triu_indices(self.n, 1)


def _limits(team: Team, sheet_margin: float, inset: float) -> _Limits | None:
    """The requirements; None when a necessary condition fails: no object height left, a
    pair that must be closer than two radii, or an inset no taut triangle the search designs
    can hold (a triangle's inradius is at most its longest side over 2 sqrt(3))."""
    s, vm = float(team.sheet.size), team.sheet.vertices
    iu, ju = np.triu_indices(team.n, 1)
    m = dict(z_min=team.height_safety + _tol.SQUEEZE_HEIGHT_MARGIN, inset=inset,
             sep=2 * team.robot_radius,
             dmax=np.linalg.norm(vm[iu] - vm[ju], axis=1) - sheet_margin)
    zr = team.hold_height / s
    d_hi, d_lo = zr - m["z_min"] / s, MIN_DEPTH_FRACTION * zr
    if d_hi <= d_lo or np.any(m["dmax"] < m["sep"]) or inset > m["dmax"].max() / 12 ** 0.5:
        return None
    return _Limits(vm / s, s, d_hi, d_lo, inset / s, m["sep"] / s, m["dmax"] / s,
                   _tol.SQUEEZE_SLACK / s, m)


def _pocket(R: np.ndarray, V: np.ndarray, taut: tuple[int, ...]
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The state with the cables ``taut`` taut, for robots ``R`` (B, N, 2) (normalised).

    Solves :math:`g_i = g_{K_0}` (:math:`i \\in K`), :math:`\\mathbf{r}_o = \\sum w_i
    \\mathbf{r}_i`, :math:`\\mathbf{v}_o = \\sum w_i \\mathbf{v}_i`, :math:`\\sum w_i = 1`
    (linear: the :math:`g_i` differ by affine terms). Returns :math:`\\mathbf{r}_o` (B, 2),
    :math:`\\mathbf{v}_o` (B, 2), :math:`w` (B, k), :math:`d^2` (B,) and the least
    curvature of the face (B,; > 0: a strict minimum of the height when :math:`w > 0`).
    Singular systems get weights and curvature -1.
    """
    B, k, K = R.shape[0], len(taut), list(taut)
    RK, VK = R[:, K], V[K]
    dR = RK[:, 1:] - RK[:, :1]
    dV = np.broadcast_to(VK[1:] - VK[:1], dR.shape)
    A = np.zeros((B, k + 4, k + 4))
    b = np.zeros((B, k + 4))
    A[:, :k - 1, :2] = 2 * dR
    A[:, :k - 1, 2:4] = -2 * dV
    b[:, :k - 1] = ((RK[:, 1:] ** 2).sum(2) - (RK[:, :1] ** 2).sum(2)
                    - (VK[1:] ** 2).sum(1) + (VK[0] ** 2).sum())
    rows = np.arange(4)
    A[:, k - 1 + rows, rows] = 1.0
    A[:, k - 1:k + 1, 4:] = -RK.transpose(0, 2, 1)
    A[:, k + 1:k + 3, 4:] = -VK.T
    A[:, k + 3, 4:] = 1.0
    b[:, k + 3] = 1.0
    bad = ~(np.abs(np.linalg.det(A)) > _tol.SQUEEZE_SINGULAR)
    A[bad] = np.eye(k + 4)
    z = np.linalg.solve(A, b[..., None])[..., 0]
    ro, vo, w = z[:, :2], z[:, 2:4], z[:, 4:]
    d2 = ((vo - VK[0]) ** 2).sum(1) - ((ro - RK[:, 0]) ** 2).sum(1)
    curv = _curvature(np.concatenate([dR, -dV], axis=2))
    w[bad], curv[bad] = -1.0, -1.0
    return ro, vo, w, d2, curv


def _curvature(G: np.ndarray) -> np.ndarray:
    """Least eigenvalue of diag(1, 1, -1, -1) on the null space of the rows of ``G``
    (B, k - 1, 4): the face where the taut cables stay taut (1 for a vertex of the hull)."""
    m = G.shape[1]
    if m >= 4:
        return np.ones(G.shape[0])
    null = np.linalg.svd(G)[2][:, m:]
    C = np.einsum("bpi,i,bqi->bpq", null, np.array([1.0, 1.0, -1.0, -1.0]), null)
    return np.linalg.eigvalsh(C)[:, 0]


def _cut_value(R: np.ndarray, V: np.ndarray, cut: Cut) -> np.ndarray:
    """How far (B,) robots ``R`` (B, N, 2) are past removing a stable state (> 0: removed)."""
    taut, form, m = cut
    ro, vo, w, d2, curv = _pocket(R, V, taut)
    if form == "weight":
        return -w[:, m]
    if form == "curvature":
        return -curv
    return d2 - (((vo - V[m]) ** 2).sum(1) - ((ro - R[:, m]) ** 2).sum(1))


def _nearest_cut(R: np.ndarray, V: np.ndarray, taut: tuple[int, ...]) -> Cut:
    """The cut nearest to removing the stable state with ``taut`` taut at robots ``R``."""
    cuts: list[Cut] = [(taut, "weight", i) for i in range(len(taut))]
    cuts.append((taut, "curvature", 0))
    cuts += [(taut, "cable", j) for j in range(len(V)) if j not in taut]
    values = [float(_cut_value(R[None], V, c)[0]) for c in cuts]
    return cuts[int(np.argmax(values))]


class _Program:
    """Minimise the half-width ``t`` over ``u = (robots (N, 2) flattened, t)`` (normalised)
    with the cables ``taut`` holding the object; ``g(u) >= 0`` holds every requirement.
    With ``target`` set, ``t`` is fixed and the last variable is a margin ``m`` added to the
    least inset and height (to be maximised)."""

    def __init__(self, lim: _Limits, taut: tuple[int, ...]) -> None:
        self.lim, self.taut = lim, taut
        self.target: float | None = None     # set: half-width fixed, maximise the margin
        self.slack = np.array([j for j in range(lim.n) if j not in taut], dtype=int)
        a, b, c = (lim.V[i] for i in taut)
        e, f = b - a, c - a
        self.orient = float(np.sign(e[0] * f[1] - e[1] * f[0]))   # robots keep the sheet's
        self.cuts: list[Cut] = []

    def values(self, U: np.ndarray) -> np.ndarray:
        """Constraint values (B, m) of decision vectors ``U`` (B, 2N + 1)."""
        lim, n = self.lim, self.lim.n
        R = U[:, :2 * n].reshape(len(U), n, 2)
        t, m = (U[:, -1:], 0.0) if self.target is None else (self.target, U[:, -1:])
        ro, vo, w, d2, curv = _pocket(R, lim.V, self.taut)
        depth = np.sqrt(np.maximum(d2, 0.0))[:, None]
        parts = [curv[:, None] - _tol.SQUEEZE_MIN_CURVATURE, lim.d_hi - m - depth,
                 (d2 - lim.d_lo ** 2)[:, None], self._inset(R, ro) - lim.inset - m]
        if len(self.slack):
            length = np.linalg.norm(vo[:, None] - lim.V[self.slack], axis=2)
            chord = np.sqrt(((ro[:, None] - R[:, self.slack]) ** 2).sum(2) + depth ** 2)
            parts.append(length - chord - lim.slack)
        iu, ju = lim.pairs
        dist = np.linalg.norm(R[:, iu] - R[:, ju], axis=2)
        parts += [dist - lim.sep, lim.dmax - dist, t - R[:, :, 1], t + R[:, :, 1]]
        parts += [_cut_value(R, lim.V, c)[:, None] - _tol.SQUEEZE_CUT_MARGIN for c in self.cuts]
        return np.concatenate(parts, axis=1) - _tol.STRICT_SLACK

    def _inset(self, R: np.ndarray, ro: np.ndarray) -> np.ndarray:
        """Signed distances (B, 3) of the object inside the taut robots' triangle."""
        P = R[:, list(self.taut)]
        E = np.roll(P, -1, axis=1) - P
        Q = ro[:, None] - P
        cross = E[..., 0] * Q[..., 1] - E[..., 1] * Q[..., 0]
        return self.orient * cross / np.maximum(np.linalg.norm(E, axis=2), _tol.SQUARE_FLOOR)

    def fun(self, u: np.ndarray) -> np.ndarray:
        return self.values(u[None])[0]

    def jac(self, u: np.ndarray) -> np.ndarray:
        """Forward differences, every column in one batch."""
        h = _tol.SQUEEZE_FD_STEP
        g = self.values(np.vstack([u, u + h * np.eye(len(u))]))
        return ((g[1:] - g[0]) / h).T


@dataclass(frozen=True)
class _Candidate:
    """A formation forward kinematics accepted."""

    width: float            # extent of the robots' centres along y, m
    margin: float           # least of its inset and height margins, m
    robots: np.ndarray      # (N, 2), m
    state: Equilibrium


def _accept(solver: FKSolver, lim: _Limits, R: np.ndarray) -> _Candidate | None:
    """Robots ``R`` (N, 2, m) as a candidate if forward kinematics alone confirms every
    requirement (one stable state, its height and inset, the pair distances)."""
    iu, ju = lim.pairs
    dist = np.linalg.norm(R[iu] - R[ju], axis=1)
    m = lim.metres
    if not (np.all(np.isfinite(R)) and np.all(dist >= m["sep"]) and np.all(dist <= m["dmax"])):
        return None
    try:
        stable = solver.solve(np.ascontiguousarray(R, dtype=float), check=False).stable
    except TautError:
        return None
    if len(stable) != 1:
        return None
    e = stable[0]
    up = e.height - m["z_min"]
    inside = hull_inset(R[list(e.taut)], e.object[:2]) - m["inset"]
    if up < 0 or inside < 0 or not tolerates(solver, R, e,
                                             m["z_min"] - _tol.SQUEEZE_HEIGHT_MARGIN):
        return None
    return _Candidate(float(np.ptp(R[:, 1])), min(up, inside), R, e)


def _search(solver: FKSolver, prog: _Program, u0: np.ndarray) -> list[_Candidate]:
    """Every accepted SLSQP iterate of ``prog`` from ``u0``; cuts are added to ``prog``."""
    lim, n, found = prog.lim, prog.lim.n, []
    bounds = [(-BOX, BOX)] * (2 * n) + [(0.0, BOX if prog.target is None else prog.target)]
    cons = [{"type": "ineq", "fun": prog.fun, "jac": prog.jac}]
    grad = np.zeros(len(u0))
    grad[-1] = 1.0 if prog.target is None else -MARGIN_SCALE
    u = u0
    for _ in range(ROUNDS):
        its = [u]
        try:
            res = minimize(lambda x: grad @ x, u, jac=lambda x: grad, method="SLSQP",
                           bounds=bounds, constraints=cons,
                           callback=lambda x: its.append(x.copy()),
                           options={"maxiter": MAX_ITER, "ftol": _tol.FORMATION_FTOL})
        except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
            break
        its.append(res.x)
        found += [c for c in (_accept(solver, lim, x[:2 * n].reshape(n, 2) * lim.s)
                              for x in its) if c is not None]
        R = res.x[:2 * n].reshape(n, 2)
        if not np.all(np.isfinite(R)) or prog.fun(res.x).min() < -_tol.FORMATION_FEAS_TOL:
            break
        try:
            stable = solver.solve(R * lim.s).stable
        except TautError:
            break
        others = [e.taut for e in stable if e.taut != prog.taut and len(e.taut) <= 5]
        if not others or len(stable) == 1:
            break
        prog.cuts += [_nearest_cut(R, lim.V, k) for k in others]
        u = res.x
    return found


def _order(lim: _Limits, u0: np.ndarray) -> list[_Program]:
    """Triples of taut cables (not collinear on the sheet), the start's program least
    violated first (ties in lexicographic order)."""
    progs = [p for p in (_Program(lim, t) for t in itertools.combinations(range(lim.n), 3))
             if p.orient != 0]
    viol = [-float(np.minimum(p.fun(u0), 0.0).sum()) for p in progs]
    return [progs[i] for i in np.argsort(viol, kind="stable")]


def _start_robots(team: Team, sheet_margin: float, start: Formation | None) -> np.ndarray:
    """The start's robots (N, 2), m: ``start``, else the narrow all-taut formation (the
    compact one for three robots), else a contracted copy of the sheet."""
    if start is None:
        start = _optimal_formation(team, "narrow" if team.n > 3 else "compact",
                                   sheet_margin=sheet_margin)
    if start is not None:
        return np.array(start.robots, dtype=float)
    V = team.sheet.vertices
    return START_SQUEEZES[0] * (V - V.mean(axis=0))


def _turned(R: np.ndarray) -> np.ndarray:
    """``R`` (N, 2) turned so that its narrowest direction is y (the least width of a convex
    polygon is across one of its edges)."""
    hull = convex_hull(R)
    if hull is None:
        return R
    E = np.roll(hull, -1, axis=0) - hull
    a = -np.arctan2(E[:, 1], E[:, 0])
    y = np.sin(a)[:, None] * R[:, 0] + np.cos(a)[:, None] * R[:, 1]
    k = int(np.argmin(np.ptp(y, axis=1)))
    c, s = np.cos(a[k]), np.sin(a[k])
    return R @ np.array([[c, s], [-s, c]])


def _finish(team: Team, solver: FKSolver, lim: _Limits, cand: _Candidate) -> Formation | None:
    """The :class:`Formation` of a candidate, turned to its narrowest direction and with the
    object's projection at the origin (each step re-accepted by forward kinematics)."""
    for R in (_turned(cand.robots), cand.robots):
        c = _accept(solver, lim, R)
        c = None if c is None else _accept(solver, lim, R - c.state.object[:2])
        if c is None:
            continue
        e, robots, w = c.state, np.array(c.robots), np.zeros(team.n)
        robots.setflags(write=False)
        w[list(e.taut)] = e.weights
        m = formation_metrics(robots, margin=team.clearance, object_height=e.height,
                              height_margin=team.height_safety)
        reach = float(np.linalg.norm(robots - e.object[:2], axis=1).max()) + team.clearance
        # max_height 0: a slack cable's stretch of sheet sags and may hang below the object
        # (the object is the sheet's lowest point only along taut cables), so a squeezed
        # formation never passes over an obstacle (our rule).
        return Formation(robots, e.height, np.array(e.contact), w, "squeezed", m.size,
                         0.0, m.min_distance, m.max_obstacle_diameter, reach, c.width)
    return None  # pragma: no cover - turning and translating keep the state


def squeezed_formation(team: Team, *, sheet_margin: float = 0.0, width: float | None = None,
                       inset: float | None = None, start: Formation | None = None
                       ) -> Formation | None:
    """The narrowest formation holding the object stably with some cables slack (module
    docstring: requirements, method, the papers and what is ours).

    Parameters
    ----------
    team : Team
    sheet_margin : float
        Every robot pair stays this far inside its sheet distance, m.
    width : float, optional
        Stop at the first formation at most this wide (m) and return the most robust such
        one (largest of the least inset and height margins); when none is found, the
        narrowest found is returned. Default: minimise the width.
    inset : float, optional
        Least distance of the object's projection inside the convex hull of the robots
        whose cables are taut, m (default ``team.robot_radius``). A force-closure margin:
        the object is not on the edge of the taut robots' polygon, where the least
        sideways push moves it (it keeps the answer from degenerating to a line).
    start : Formation, optional
        Where the search starts (default: ``optimal_formation(team, kind="narrow")``, the
        compact one for three robots).

    Returns
    -------
    Formation or None
        ``kind="squeezed"``, the narrow direction on y, robots relative to the object's
        projection, ``weights`` zero for slack cables, ``cost`` the width (m),
        ``max_height`` 0 (a slack cable's stretch of sheet may sag below the object, so the
        formation passes over no obstacle). None when no formation meets the requirements.
    """
    require_instance(team, Team, "team")
    sheet_margin = as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_MARGIN_M, "m",
                              positive=False)
    if width is not None:
        width = as_bounded(width, "width", MAX_SHEET_LENGTH, "m", positive=False)
    if inset is not None:
        inset = as_bounded(inset, "inset", MAX_SHEET_LENGTH, "m", positive=False)
    if start is not None:
        require_instance(start, Formation, "start")
        if start.n != team.n:
            raise InvalidInputError("start", f"has {start.n} robots, the team {team.n}")
    return _squeezed_formation(team, sheet_margin, width, inset, start)


def _squeezed_formation(team: Team, sheet_margin: float, width: float | None = None,
                        inset: float | None = None, start: Formation | None = None
                        ) -> Formation | None:
    """:func:`squeezed_formation` on validated inputs."""
    inset = team.robot_radius if inset is None else inset
    lim = _limits(team, sheet_margin, inset)
    if lim is None:
        return None
    solver = FKSolver(team.carrier)
    R_start = _start_robots(team, sheet_margin, start) / lim.s
    goal = width if width is not None else 2 * inset + _tol.SQUEEZE_WIDTH_TOL
    found: list[_Candidate] = []
    for squeeze in START_SQUEEZES:
        R0 = R_start * np.array([1.0, squeeze])
        u0 = np.append(R0.ravel(), np.abs(R0[:, 1]).max())
        for prog in _order(lim, u0)[:MAX_TRIPLES]:
            found += _search(solver, prog, u0)
            fit = [c for c in found if c.width <= goal]
            if fit and width is not None:
                return _finish(team, solver, lim, _robust(solver, prog, fit, width))
            if fit:
                break
        if any(c.width <= goal for c in found):
            break
    best = min(found, key=lambda c: (c.width, -c.margin)) if found else None
    return None if best is None else _finish(team, solver, lim, best)


def _robust(solver: FKSolver, prog: _Program, fit: list[_Candidate], width: float
            ) -> _Candidate:
    """The candidate at most ``width`` wide with the largest margin: ``prog`` maximises the
    margin with the width fixed, from the best of ``fit``."""
    c = max(fit, key=lambda c: c.margin)
    R = c.robots / prog.lim.s
    R[:, 1] -= (R[:, 1].max() + R[:, 1].min()) / 2
    prog.target = width / 2 / prog.lim.s
    more = _search(solver, prog, np.append(R.ravel(), 0.0))
    return max(fit + [c for c in more if c.width <= width], key=lambda c: c.margin)
