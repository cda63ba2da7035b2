"""Quasi-static transport simulation: what the object does while the robots move.

Model (FK paper Sec. II; DESIGN.md Sec. 1-5). At every instant the object rests at a
strict local minimum of :math:`F(x) = \\max_i(|\\mathbf{r}_o - \\mathbf{r}_i|^2 -
|\\mathbf{v}_o - \\mathbf{v}_i|^2)` over :math:`x = (\\mathbf{r}_o, \\mathbf{v}_o)` (the depth is
:math:`d^2 = -F`). The robots move slowly (quasi-static), so the object follows its local
minimum continuously (its *branch*). For a fixed taut set ``T`` the stationary point is
unique (the Lagrange system of the FK paper, eqs. 10-14, is linear), so a branch is
followed by re-solving the current taut set at each step; it stays valid while the weights
stay non-negative, slack cables stay slack, the object stays above ground and the reduced
Hessian stays positive definite (the same tests as :func:`forward_kinematics`).

When the current taut set stops being valid between steps ``t-1`` and ``t``, the formation
is interpolated linearly and the crossing fraction :math:`s^*` is located by grid
refinement (to 1e-10 of a step). Just past it the branch is continued if possible: first
among the taut sets one cable away (drop, add or swap one), then among the stable states
of full forward kinematics, accepting a state within a small tolerance of the state at
:math:`s^*` (a *taut-set change*: a cable went slack or became taut). Otherwise the
branch has ended and the object *jumps*: it rolls to the minimum reached by steepest
descent of ``F`` (an epsilon-subgradient method for this max of quadratics) from its last
state, and the event records the drop height. If the object reaches the ground
(:math:`z_o \\le 0`) it is *lost* until a stable state exists again (*recovered*, at the
lowest one). Tracking then continues to the end of the step. Taut-set-change events are
reported wherever the reported taut set (the exact maximiser set, as in FK) changes
between steps without a jump.

Degenerate states (more than 5 taut cables, e.g. every cable of an IK formation with
N >= 6) are followed through a *support*: at most 5 taut cables with affinely independent
lifted points and non-negative weights for the same state (Caratheodory), so the same
small solve applies.

Decisions where the papers are silent: events are detected at the trajectory's sampling
(a branch that ends and reappears between two samples is not seen); a jump's destination
is the descent's end point (not the nearest stable state, as vvcm-rs picks); sub-step
positions are linear interpolations of the formations.

Tracking is vectorised over chunks of steps (one batched small solve per chunk), so the
cost per step is a few microseconds; full FK is called only at events.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.optimize import linprog, nnls

from .._validate import as_array
from ..errors import InvalidInputError, InvalidTrajectoryError
from ._kernel import (CURVATURE_TOL, WEIGHT_TOL, Frame, height_ok, reduced_hessian_min_eig,
                      solve_candidates, taut_masks)
from .fk import _check_mass, _check_sheet, forward_kinematics, forward_kinematics_batch
from .model import Sheet, check_formations, check_hold_height
from .results import GRAVITY, Equilibrium

__all__ = ["SimulationEvent", "SimulationResult", "simulate"]

EventKind = Literal["taut_change", "jump", "lost", "recovered"]

#: Continuation tolerance at an event (times the sheet size), plus a motion-based term.
CONTINUATION_RTOL = 1e-6
#: Precision (fraction of a step) to which an event is located.
EVENT_STEP_TOL = 1e-10
#: Teams up to this size use FK's complete 'subsets' method at events.
SUBSETS_UP_TO = 10
#: A descent has arrived when the pieces active at its point (within 1e-6) form a stable
#: state this close (times the sheet size) to it.
ARRIVAL_RTOL = 0.05
_J = np.array([1.0, 1.0, -1.0, -1.0])


@dataclass(frozen=True, eq=False)
class SimulationEvent:
    """Something discontinuous that happened between steps ``step - 1`` and ``step``.

    Attributes
    ----------
    step : int
        First trajectory step whose state reflects the event.
    fraction : float
        Where between the two steps (0..1, formations interpolated linearly).
    kind : {"taut_change", "jump", "lost", "recovered"}
        ``taut_change``: the taut set changed along a continuous branch. ``jump``: the
        branch ended and the object rolled to another minimum. ``lost``: no stable
        state exists (e.g. the object would touch the ground); states are NaN until
        ``recovered`` (the lowest stable state once one exists again).
    taut_before, taut_after : tuple of int
        0-based taut sets.
    object_before, object_after : ndarray, shape (3,)
        Object positions just before and after (NaN when lost).
    drop : float
        Height lost, :math:`z_{before} - z_{after}` (about 0 for taut-set changes).
    """

    step: int
    fraction: float
    kind: EventKind
    taut_before: tuple[int, ...]
    taut_after: tuple[int, ...]
    object_before: np.ndarray
    object_after: np.ndarray
    drop: float


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Object state at every step of a quasi-static simulation.

    Attributes
    ----------
    object : ndarray, shape (T, 3)
        :math:`\\mathbf{p}_o` per step (NaN while lost).
    contact : ndarray, shape (T, 2)
        :math:`\\mathbf{v}_o` per step.
    taut : tuple of tuple of int
        Taut set per step (0-based).
    weights : ndarray, shape (T, N)
        Load shares (0 on slack cables).
    tensions : ndarray, shape (T, N), or None
        Cable tensions in N when a mass was given (0 on slack cables).
    events : tuple of SimulationEvent
        In time order.
    formations : ndarray, shape (T, N, 2)
    hold_height : float
    mass : float or None
    """

    object: np.ndarray
    contact: np.ndarray
    taut: tuple[tuple[int, ...], ...]
    weights: np.ndarray
    tensions: np.ndarray | None
    events: tuple[SimulationEvent, ...]
    formations: np.ndarray
    hold_height: float
    mass: float | None

    @property
    def jumps(self) -> tuple[SimulationEvent, ...]:
        """The events where the object jumped to another minimum."""
        return tuple(e for e in self.events if e.kind == "jump")

    @property
    def taut_mask(self) -> np.ndarray:
        """Bool (T, N): taut cables per step."""
        m = np.zeros(self.weights.shape, dtype=bool)
        for t, s in enumerate(self.taut):
            m[t, list(s)] = True
        return m

    def __len__(self) -> int:
        return int(self.object.shape[0])


@dataclass
class _State:
    """Object state; ``support`` (3..5 cables, affinely independent lifted points, the
    set that is re-solved along the branch) is a subset of ``taut`` (the exact maximiser
    set, reported; larger only at degenerate states such as all-taut IK formations)."""

    support: tuple[int, ...]
    taut: tuple[int, ...]
    ro: np.ndarray
    vo: np.ndarray
    z: float
    w: np.ndarray                          # (N,)

    @property
    def point(self) -> np.ndarray:
        return np.concatenate([self.ro, self.vo, [self.z]])


def _support(sheet: Sheet, R: np.ndarray, z: float, e: Equilibrium) -> tuple[int, ...]:
    """A subset of the taut set to follow: at most 5 cables whose lifted points are
    affinely independent and span the same face, carrying non-negative weights for the
    same state (a basic solution of the weight equations, Caratheodory), so that solving
    it reproduces the state."""
    T = np.array(e.taut, dtype=np.intp)
    frame = Frame.build(sheet.vertices, R[None], z, sheet.size)
    P = frame.P[0, T]

    def rank(rows: np.ndarray) -> int:
        if len(rows) < 2:
            return len(rows)
        sv = np.linalg.svd(P[rows[1:]] - P[rows[:1]], compute_uv=False)
        return 1 + int(np.sum(sv > 1e-9 * max(1.0, sv[0])))

    everything = np.arange(len(T))
    full = rank(everything)
    if len(T) <= 5 and full == len(T):
        return tuple(int(i) for i in T)
    E = np.vstack([np.ones(len(T)), frame.R[0, T].T, frame.V[T].T])
    lp = linprog(-np.asarray(e.weights), A_eq=E, b_eq=E @ e.weights,
                 bounds=[(0, None)] * len(T), method="highs-ds")
    w = lp.x if lp.success else np.asarray(e.weights)
    chosen: list[int] = []
    for i in np.argsort(-w):
        if len(chosen) == full:
            break
        if rank(np.array(chosen + [int(i)])) == len(chosen) + 1:
            chosen.append(int(i))
    return tuple(sorted(int(T[i]) for i in chosen))


def _from_equilibrium(e: Equilibrium, sheet: Sheet, R: np.ndarray, z: float) -> _State:
    w = np.zeros(sheet.n)
    w[list(e.taut)] = e.weights
    return _State(_support(sheet, R, z, e), e.taut, e.object[:2].copy(), e.contact.copy(),
                  float(e.object[2]), w)


def _solve_sets(sheet: Sheet, R: np.ndarray, z: float, form: np.ndarray, idx: np.ndarray):
    """Solve taut sets ``idx`` (M, 5), padded with -1, 3..5 cables each, on formations
    ``R[form]`` (R (B, N, 2)), with the tests of :func:`forward_kinematics`.

    Returns valid (M,), ro (M, 2), vo (M, 2), zo (M,), w (M, N) in world units, and the
    exact taut sets (M, N) (NaN/0/False on rows whose system is singular)."""
    M, N = len(form), R.shape[1]
    frame = Frame.build(sheet.vertices, R, z, sheet.size)
    sol = solve_candidates(frame, form, idx, independent=True)
    valid = np.zeros(M, dtype=bool)
    ro = np.full((M, 2), np.nan)
    vo = np.full((M, 2), np.nan)
    zo = np.full(M, np.nan)
    w = np.zeros((M, N))
    tight = np.zeros((M, N), dtype=bool)
    if len(sol.form) == 0:
        return valid, ro, vo, zo, w, tight
    ok = height_ok(frame, sol)
    ok_taut, tight_sol = taut_masks(frame, sol)
    members = sol.subset >= 0
    ok &= ok_taut & (np.where(members, sol.w, np.inf).min(axis=1) >= -WEIGHT_TOL)
    ok &= reduced_hessian_min_eig(frame, sol.form, sol.subset) > CURVATURE_TOL
    src, f = sol.source, sol.form
    valid[src] = ok
    ro[src] = sol.ro * frame.scale + frame.r_centre[f]
    vo[src] = sol.vo * frame.scale + frame.v_centre
    zo[src] = z - np.sqrt(np.maximum(sol.depth2, 0.0)) * frame.scale
    rows, slots = np.nonzero(members)
    w[src[rows], sol.subset[rows, slots]] = sol.w[rows, slots]
    tight[src] = tight_sol
    return valid, ro, vo, zo, w, tight


def _members(mask_or_idx: np.ndarray) -> tuple[int, ...]:
    a = np.asarray(mask_or_idx)
    idx = np.flatnonzero(a) if a.dtype == bool else a
    return tuple(sorted(int(i) for i in idx))


def _branch(sheet: Sheet, R: np.ndarray, z: float, taut: tuple[int, ...]):
    """One taut set (3..5 cables) on every formation of ``R`` (C, N, 2); see
    :func:`_solve_sets`."""
    C = R.shape[0]
    idx = np.full((C, 5), -1, dtype=np.intp)
    idx[:, :len(taut)] = taut
    return _solve_sets(sheet, R, z, np.arange(C), idx)


def _neighbour_sets(taut: tuple[int, ...], N: int) -> np.ndarray:
    """Taut sets one cable away from ``taut`` (drop one, add one, or swap one), 3..5
    cables, as rows padded with -1: the candidates for a continuous taut-set change."""
    cur = set(taut)
    out = []
    for i in taut:
        if len(cur) - 1 >= 3:
            out.append(sorted(cur - {i}))
    others = [j for j in range(N) if j not in cur]
    for j in others:
        if len(cur) + 1 <= 5:
            out.append(sorted(cur | {j}))
        for i in taut:
            if len(cur) >= 3:
                out.append(sorted((cur - {i}) | {j}))
    idx = np.full((len(out), 5), -1, dtype=np.intp)
    for k, row in enumerate(out):
        idx[k, :len(row)] = row
    return idx


def _min_norm_combination(G: np.ndarray) -> np.ndarray:
    """Point of minimum norm in the convex hull of the rows of ``G`` (k, 4)."""
    if len(G) == 1:
        return G[0]
    M = 1e3 * max(1.0, float(np.abs(G).max()))
    A = np.vstack([G.T, M * np.ones(len(G))])
    b = np.zeros(A.shape[0])
    b[-1] = M
    lam, _ = nnls(A, b)
    total = lam.sum()
    if total <= 0:
        return G[np.argmin(np.linalg.norm(G, axis=1))]
    return (lam / total) @ G


def _descend(P: np.ndarray, x0: np.ndarray, arrive, floor: float, maxit: int = 3000
             ) -> np.ndarray | None:
    """Steepest descent of F(x) = q(x) + max_i (a_i . x + b_i) from ``x0`` (normalised
    units; P (N, 5) lifted points): epsilon-steepest-descent directions (minimum-norm
    element of the gradients of the epsilon-active pieces) with Armijo backtracking, eps
    shrinking as the method stalls. Every few iterations ``arrive(active, x)`` is asked
    whether the pieces active at ``x`` already identify a stable minimum (it returns a
    result or None); otherwise the descent ends at a (Clarke) stationary point and
    returns ``x``. Returns None when F drops below ``floor`` (the object reaches the
    ground, :math:`d \\ge z_r`)."""
    A, b = P[:, :4], P[:, 4]

    def F(x: np.ndarray) -> float:
        return float(x @ (_J * x) + (A @ x + b).max())

    x = x0.copy()
    f = F(x)
    eps, t = 1e-3, 1.0
    for it in range(maxit):
        vals = x @ (_J * x) + A @ x + b
        top = vals.max()
        if it % 4 == 0:
            found = arrive(np.flatnonzero(vals >= top - 1e-6), x)
            if found is not None:
                return found
        active = vals >= top - eps
        g = _min_norm_combination(2 * _J * x + A[active])
        gn2 = float(g @ g)
        if gn2 < 1e-22:
            if eps < 1e-12:
                break
            eps *= 0.1
            continue
        t = min(1.0, 4.0 * t)
        while True:
            trial = x - t * g
            ft = F(trial)
            if ft <= f - 1e-4 * t * gn2:
                break
            t *= 0.5
            if t < 1e-14:
                break
        if t < 1e-14:
            t = 1.0
            if eps < 1e-12:
                break
            eps *= 0.1
            continue
        x, f = trial, ft
        if f < floor:
            return None
    return x


def _nearest(stable: tuple[Equilibrium, ...], point: np.ndarray) -> tuple[int, float]:
    pts = np.array([np.concatenate([e.object[:2], e.contact, [e.object[2]]]) for e in stable])
    d = np.linalg.norm(pts - point, axis=1)
    j = int(np.argmin(d))
    return j, float(d[j])


class _Tracker:
    def __init__(self, sheet: Sheet, z: float):
        self.sheet, self.z = sheet, z
        self.N = sheet.n

    def trackable(self, state: _State) -> bool:
        return 3 <= len(state.support) <= 5

    def valid_at(self, state: _State, R: np.ndarray) -> tuple[bool, _State | None]:
        if not self.trackable(state):
            return False, None
        valid, ro, vo, zo, w, tight = _branch(self.sheet, R[None], self.z, state.support)
        if not valid[0]:
            return False, None
        return True, _State(state.support, _members(tight[0]), ro[0], vo[0], float(zo[0]),
                            w[0])

    def crossing(self, state: _State, R0: np.ndarray, R1: np.ndarray, s0: float
                 ) -> tuple[float, float, _State]:
        """Last valid fraction s_lo (with its state) and first invalid s_hi > s_lo."""
        lo, hi, at_lo = s0, 1.0, state
        while hi - lo > EVENT_STEP_TOL:
            s = np.linspace(lo, hi, 18)[1:-1]
            R = (1 - s)[:, None, None] * R0 + s[:, None, None] * R1
            valid, ro, vo, zo, w, tight = _branch(self.sheet, R, self.z, state.support)
            bad = np.flatnonzero(~valid)
            k = int(bad[0]) if len(bad) else len(s)
            if k > 0:
                lo = float(s[k - 1])
                at_lo = _State(state.support, _members(tight[k - 1]), ro[k - 1], vo[k - 1],
                               float(zo[k - 1]), w[k - 1])
            if k < len(s):
                hi = float(s[k])
        return lo, hi, at_lo

    def stable_states(self, R: np.ndarray) -> tuple[Equilibrium, ...]:
        """Stable FK states of one formation. Events happen at degenerate places (just
        past a taut-set change, or leaving an all-taut IK formation) where the hull-based
        method can miss states, so small teams use the complete 'subsets' method and
        larger ones fall back to it when 'fast' finds none."""
        method = "subsets" if self.N <= SUBSETS_UP_TO else "fast"
        stable = forward_kinematics(self.sheet, R, self.z, method=method).stable
        if not stable and method == "fast":
            stable = forward_kinematics(self.sheet, R, self.z, method="subsets").stable
        return stable

    def settle(self, R: np.ndarray, before: _State, cont_tol: float
               ) -> tuple[_State | None, EventKind | None]:
        """State at formation ``R`` reached from ``before`` (continuation or descent).

        A continuation is tried first among the taut sets one cable away from the
        current one (no FK call, and exact at transitions where forward kinematics'
        tolerance-based taut sets are ambiguous), then among FK's stable states; failing
        both, the object rolls: steepest descent from ``before``, then the descent's
        end point's active set (or the nearest stable FK state)."""
        N, size = self.N, self.sheet.size
        if self.trackable(before):
            idx = _neighbour_sets(before.support, N)
            if len(idx):
                valid, ro, vo, zo, w, tight = _solve_sets(self.sheet, R[None], self.z,
                                                          np.zeros(len(idx), np.intp), idx)
                pts = np.column_stack([ro, vo, zo])
                dist = np.where(valid, np.linalg.norm(pts - before.point, axis=1), np.inf)
                k = int(np.argmin(dist))
                if dist[k] <= cont_tol:
                    new = _State(_members(idx[k][idx[k] >= 0]), _members(tight[k]), ro[k],
                                 vo[k], float(zo[k]), w[k])
                    return new, ("taut_change" if new.taut != before.taut else None)
        stable = self.stable_states(R)
        if stable:
            j, dist = _nearest(stable, before.point)
            if dist <= cont_tol:
                new = _from_equilibrium(stable[j], self.sheet, R, self.z)
                return new, ("taut_change" if new.taut != before.taut else None)
        frame = Frame.build(self.sheet.vertices, R[None], self.z, size)
        P = frame.P[0]

        def to_world(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return x[:2] * size + frame.r_centre[0], x[2:] * size + frame.v_centre

        def arrive(active: np.ndarray, x: np.ndarray) -> _State | None:
            if not 3 <= len(active) <= 5:
                return None
            idx = np.full((1, 5), -1, dtype=np.intp)
            idx[0, :len(active)] = active
            valid, ro, vo, zo, w, tight = _solve_sets(self.sheet, R[None], self.z,
                                                      np.zeros(1, np.intp), idx)
            ro_x, vo_x = to_world(x)
            near = np.linalg.norm(np.r_[ro[0] - ro_x, vo[0] - vo_x]) <= ARRIVAL_RTOL * size
            if not (valid[0] and near):
                return None
            return _State(_members(active), _members(tight[0]), ro[0], vo[0], float(zo[0]),
                          w[0])

        x0 = np.concatenate([(before.ro - frame.r_centre[0]) / size,
                             (before.vo - frame.v_centre) / size])
        out = _descend(P, x0, arrive, -frame.z ** 2)
        if isinstance(out, _State):
            return out, "jump"
        if out is None:
            return None, "lost"
        vals = out @ (_J * out) + P[:, :4] @ out + P[:, 4]
        ro, vo = to_world(out)
        zo = self.z - np.sqrt(max(-float(vals.max()), 0.0)) * size
        if not stable:
            return None, "lost"
        j, _ = _nearest(stable, np.concatenate([ro, vo, [zo]]))
        return _from_equilibrium(stable[j], self.sheet, R, self.z), "jump"


def _event(step: int, frac: float, kind: EventKind, a: _State | None, b: _State | None
           ) -> SimulationEvent:
    nan3 = np.full(3, np.nan)
    pa = nan3 if a is None else np.array([*a.ro, a.z])
    pb = nan3 if b is None else np.array([*b.ro, b.z])
    return SimulationEvent(step, frac, kind, () if a is None else a.taut,
                           () if b is None else b.taut, pa, pb, float(pa[2] - pb[2]))


def simulate(sheet: Sheet, formations: object, hold_height: float, *,
             start: object | None = None, mass: float | None = None) -> SimulationResult:
    """Quasi-static simulation of the object along a time series of formations.

    Parameters
    ----------
    sheet : Sheet
    formations : array_like, shape (T, N, 2)
        Robot positions at each step (world frame, sheet units). Steps should be small
        enough that no branch appears and vanishes between two samples.
    hold_height : float
        :math:`z_r` (> 0).
    start : array_like, shape (3,), optional
        Initial object position guess: the simulation starts at the stable equilibrium of
        ``formations[0]`` nearest to it (default: the lowest).
    mass : float, optional
        Object mass (kg) for the tensions :math:`F_i = w_i m g l_i / d`.

    Returns
    -------
    SimulationResult

    Raises
    ------
    InvalidInputError
        Bad shapes or values.
    InfeasibleFormationError
        Some formation would tear the sheet; ``.step`` is its index.
    InvalidTrajectoryError
        No stable rest state at step 0.
    """
    sheet = _check_sheet(sheet)
    mass = _check_mass(mass)
    z = check_hold_height(hold_height)
    R = check_formations(sheet, as_array(formations, "formations", ndim=3))
    T, N = R.shape[:2]
    if T == 0:
        raise InvalidInputError("formations", "needs at least one step")
    fk0 = forward_kinematics(sheet, R[0], z)
    if not fk0.stable:
        raise InvalidTrajectoryError("formations", "no stable rest state for the object at "
                                     "step 0")
    if start is None:
        first = fk0.lowest
    else:
        p = as_array(start, "start", shape=(3,))
        first = min(fk0.stable, key=lambda e: float(np.linalg.norm(e.object - p)))
    state: _State | None = _from_equilibrium(first, sheet, R[0], z)

    obj = np.full((T, 3), np.nan)
    con = np.full((T, 2), np.nan)
    wts = np.zeros((T, N))
    taut = np.zeros((T, N), dtype=bool)
    events: list[SimulationEvent] = []
    crossings: dict[int, tuple[float, np.ndarray]] = {}
    tracker = _Tracker(sheet, z)

    def store(t: int, s: _State | None) -> None:
        if s is None:
            return
        obj[t] = (*s.ro, s.z)
        con[t] = s.vo
        wts[t] = s.w
        taut[t, list(s.taut)] = True

    store(0, state)
    motion = np.abs(np.diff(R, axis=0)).max(axis=(1, 2)) if T > 1 else np.zeros(0)
    t, chunk = 1, 64
    while t < T:
        if state is None:                                  # lost: look for a rest state
            end = min(T, t + chunk)
            batch = forward_kinematics_batch(sheet, R[t:end], z)
            found = np.flatnonzero(batch.stable.any(axis=1))
            if not len(found):
                t, chunk = end, min(4 * chunk, 4096)
                continue
            t += int(found[0])
            state = _from_equilibrium(forward_kinematics(sheet, R[t], z).lowest, sheet, R[t], z)
            events.append(_event(t, 0.0, "recovered", None, state))
            store(t, state)
            t, chunk = t + 1, 64
            continue
        if tracker.trackable(state):
            end = min(T, t + chunk)
            valid, ro, vo, zo, w, tight = _branch(sheet, R[t:end], z, state.support)
            bad = np.flatnonzero(~valid)
            k = int(bad[0]) if len(bad) else end - t
            if k:
                sl = slice(t, t + k)
                obj[sl, :2], obj[sl, 2], con[sl], wts[sl] = ro[:k], zo[:k], vo[:k], w[:k]
                taut[sl] = tight[:k]
                state = _State(state.support, _members(tight[k - 1]), ro[k - 1], vo[k - 1],
                               float(zo[k - 1]), w[k - 1])
                t += k
            if not len(bad):
                chunk = min(4 * chunk, 4096)
                continue
            chunk = 64
        state = _resolve_step(tracker, state, R[t - 1], R[t], t, float(motion[t - 1]),
                              events, crossings)
        store(t, state)
        t += 1

    tensions = None
    if mass is not None:
        lengths = np.linalg.norm(sheet.vertices[None] - con[:, None, :], axis=2)
        depth = z - obj[:, 2]
        with np.errstate(invalid="ignore", divide="ignore"):
            tensions = np.where(taut, wts * mass * GRAVITY * lengths / depth[:, None], 0.0)
    taut_sets = tuple(tuple(int(i) for i in np.flatnonzero(row)) for row in taut)
    events += _taut_changes(taut_sets, obj, events, crossings)
    events.sort(key=lambda e: (e.step, e.fraction))
    return SimulationResult(obj, con, taut_sets, wts, tensions, tuple(events), R, z, mass)


def _taut_changes(taut: tuple[tuple[int, ...], ...], obj: np.ndarray,
                  events: list[SimulationEvent],
                  crossings: dict[int, tuple[float, np.ndarray]]) -> list[SimulationEvent]:
    """A ``taut_change`` event for every step whose reported taut set differs from the
    previous step's without a jump or loss there (located where a crossing was found)."""
    busy = {e.step for e in events}
    out = []
    changed = [t for t in range(1, len(taut)) if taut[t] != taut[t - 1]
               and taut[t] and taut[t - 1] and t not in busy]
    for t in changed:
        frac, where = crossings.get(t, (1.0, obj[t]))
        out.append(SimulationEvent(t, frac, "taut_change", taut[t - 1], taut[t], where.copy(),
                                   where.copy(), 0.0))
    return out


def _resolve_step(tracker: _Tracker, state: _State, R0: np.ndarray, R1: np.ndarray,
                  step: int, motion: float, events: list[SimulationEvent],
                  crossings: dict[int, tuple[float, np.ndarray]]) -> _State | None:
    """Follow the object from formation R0 (valid ``state``) to R1 through events."""
    size = tracker.sheet.size
    if motion == 0.0:
        return state
    s0 = 0.0
    for _ in range(25):
        ok, at_end = tracker.valid_at(state, R1)
        if ok:
            return at_end
        if tracker.trackable(state):
            lo, hi, before = tracker.crossing(state, R0, R1, s0)
        else:                                   # degenerate (>5 taut): leave it at once
            lo, hi, before = s0, min(1.0, s0 + 1e-6), state
        Rh = (1 - hi) * R0 + hi * R1
        if tracker.trackable(before) and _branch(tracker.sheet, Rh[None], tracker.z,
                                                 before.support)[3][0] <= 0.0:
            events.append(_event(step, hi, "lost", before, None))     # on the ground
            return None
        cont_tol = CONTINUATION_RTOL * size + 100.0 * (hi - lo) * motion
        new, kind = tracker.settle(Rh, before, cont_tol)
        if kind is not None:
            if kind == "taut_change":
                crossings.setdefault(step, (hi, np.array([*before.ro, before.z])))
            else:
                events.append(_event(step, hi, kind, before, new))
        if new is None:
            return None
        state, s0 = new, hi
        if s0 >= 1.0:
            return state
    fk = forward_kinematics(tracker.sheet, R1, tracker.z)   # pragma: no cover - safeguard
    if not fk.stable:                                       # pragma: no cover
        events.append(_event(step, 1.0, "lost", state, None))
        return None
    j, _ = _nearest(fk.stable, state.point)                 # pragma: no cover
    return _from_equilibrium(fk.stable[j], tracker.sheet, R1, tracker.z)  # pragma: no cover
