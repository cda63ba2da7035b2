"""Tension distribution: cable tensions ``t`` with ``W t + w_e = 0`` (FASTKIT eq. 17) and
``t_min <= t <= t_max`` (eq. 20), optionally also respecting the tipping constraints of the
mobile bases (eqs. 21-23), for a batch of poses. One entry point,
:func:`distribute_tensions`, four methods:

``closed_form``
    A. Pott, "An improved force distribution algorithm for over-constrained cable-driven
    parallel robots" (Computational Kinematics, 2014): the minimum-norm correction of the
    mean tension ``t_m = (t_min + t_max) / 2`` (per cable, so unequal limits are right);
    while a tension violates its limits, the most violating cable is fixed at its violated
    limit and the closed form is re-applied to the remaining cables, until the remaining
    cables number ``n``. Fully batched; conservative (it may miss feasible poses) and it
    ignores tipping when choosing tensions (it only checks them).
``lp_min_sum`` / ``lp_min_max``
    Linear programs (minimum total tension; minimum largest tension) solved by HiGHS via
    :func:`scipy.optimize.linprog`, one pose at a time; exact feasibility.
``qp_min_norm``
    The quadratic program ``min ||t||_2`` subject to the same constraints. With ``r = m - n
    <= 2`` redundant cables it is solved exactly and batched: writing ``t = W+ w + N z``
    the problem is the projection of the origin onto a polygon (or interval) in ``z``,
    whose minimiser is the interior point, the foot on an edge line, or a vertex (KKT
    active-set enumeration). Otherwise (or with ``qp_solver="daqp"``) the QP solver DAQP
    solves it pose by pose (:mod:`taut._qp`; a core dependency), or SciPy's SLSQP where DAQP
    is not installed (or with ``qp_solver="scipy"``).

Returned tensions are polished so that ``W t + w_e = 0`` holds to rounding error.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from itertools import combinations
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linprog

from ..._qp import qp_backend, solve_qp
from ...errors import InvalidInputError
from ..._validate import as_choice, as_flag
from .._batching import is_single, unbatch
from ._common import batch_outcome, constraints, feas_tol, required_wrench, svd_split
from .sliding import sliding_rows
from .._tol import QP_PARALLEL, QP_ROW_SQ, RESIDUAL_REL, SLSQP_FTOL, SLSQP_REL
from ..kinematics.cables import CableState, as_poses, cable_state, tipping_matrix
from ..model.robot import CableRobot
from ..._repr import CompactRepr

__all__ = ["TensionResult", "distribute_tensions", "METHODS"]

TensionMethod = Literal["closed_form", "lp_min_sum", "lp_min_max", "qp_min_norm"]
QPSolver = Literal["auto", "enumeration", "daqp", "scipy"]
#: The methods of :func:`distribute_tensions`.
METHODS: tuple[str, ...] = get_args(TensionMethod)


@dataclass(frozen=True, repr=False)
class TensionResult(CompactRepr):
    """Tensions for a batch of poses; for one pose every leading B axis is dropped
    (``tensions`` (m,), ``success`` a bool, ``status`` and ``binding`` a str, ``residual`` a
    float).

    Attributes
    ----------
    tensions : ndarray (B, m)
        Cable tensions, N. For infeasible poses: the method's best attempt (closed form),
        or NaN where the solver found none (LP/QP); never use them without ``success``.
    success : ndarray (B,) of bool
        True when the tensions satisfy eqs. 17 and 20 (and 21-23 when ``tipping``, the
        friction condition when ``sliding``).
    status : ndarray (B,) of str
        ``"ok"`` where ``success``, else ``"infeasible"`` (see :mod:`taut._outcome`).
    message : str
        One line. A batch: how many poses are balanced within the limits. One pose:
        whether it is wrench-feasible and, if not, why (the binding condition; for tipping
        the bases that tip).
    binding : ndarray (B,) of str
        ``""`` where ``success``; else the first condition, in the order ``"limits"``
        (eqs. 17, 20), ``"tipping"``, ``"sliding"``, whose addition makes the pose
        infeasible: for returned tensions the first condition they violate, for LP/QP
        poses without tensions the first one whose addition leaves no solution (one more
        solve per such pose).
    within_limits : ndarray (B, m) of bool
        Each returned tension within ``[t_min, t_max]`` (up to the feasibility tolerance
        scaled by the largest limit); False where no tensions were found.
    residual : ndarray (B,)
        ``max |W t + w_e|`` (N, N m); NaN where no tensions were found.
    tipping_moments : ndarray (B, E)
        Edge moments ``m_C`` of eqs. 21-23 at the returned tensions, N m (E = 0 for a
        fixed frame). Stable when all are <= 0.
    method : str
    tipping : bool
        Whether tipping constraints were imposed.
    sliding : bool
        Whether friction (sliding) constraints were imposed.
    """

    tensions: np.ndarray
    success: np.ndarray
    status: np.ndarray
    message: str
    binding: np.ndarray
    within_limits: np.ndarray
    residual: np.ndarray
    tipping_moments: np.ndarray
    method: TensionMethod
    tipping: bool
    sliding: bool


@dataclass(frozen=True)
class _Solved:
    """Tensions of a batch with the conditions they meet (private)."""

    tensions: np.ndarray        # (B, m), NaN where none were found
    found: np.ndarray           # (B,)
    residual: np.ndarray        # (B,)
    tipping_moments: np.ndarray  # (B, E)
    within: np.ndarray          # (B, m) each tension within its limits
    limits: np.ndarray          # (B,) balanced within the tension limits (eqs. 17, 20)
    tips: np.ndarray            # (B, E) edge moments above the tolerance
    slides: np.ndarray          # (B, F) friction rows violated
    slide_base: np.ndarray      # (F,) base of each friction row

    @property
    def success(self) -> np.ndarray:
        return self.limits & ~self.tips.any(axis=1) & ~self.slides.any(axis=1)


def distribute_tensions(robot: CableRobot, poses: ArrayLike,
                        method: TensionMethod = "closed_form", *,
                        external_wrench: ArrayLike | None = None, tipping: bool = True,
                        qp_solver: QPSolver = "auto", sliding: bool = True) -> TensionResult:
    """Distribute cable tensions over a batch of poses.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like, (6,), (3,), (B, 6) or (B, 3)
        Platform poses ``(x, y, z, roll, pitch, yaw)``, m and rad.
    method : {"closed_form", "lp_min_sum", "lp_min_max", "qp_min_norm"}
        See the module docstring for the sources.
    external_wrench : array_like (n,) or (B, n), optional
        Extra wrench applied to the platform on top of platform and payload weight
        (forces N, then moments N m about P, world frame).
    tipping : bool, default True
        Impose the tipping constraints of the mobile bases (FASTKIT eqs. 21-23); ignored
        for fixed frames. True by default, like every other analysis of this package: a
        distribution that tips a base over is not a physical answer. ``closed_form`` does
        not use them to choose tensions; it reports a pose feasible only when its tensions
        happen to satisfy them. Pass ``tipping=False`` for the tension limits alone.
    sliding : bool, default True
        Impose the friction condition of the mobile bases that have a friction
        coefficient (:mod:`taut.cdpr.statics.sliding`); no effect on a model without one.
        ``closed_form`` only checks it, like tipping.
    qp_solver : {"auto", "enumeration", "daqp", "scipy"}
        For ``qp_min_norm``: exact batched enumeration (needs m - n <= 2), the QP solver
        DAQP, or SciPy SLSQP. ``"auto"``: the enumeration for m - n <= 2, else DAQP when
        installed, else SLSQP.

    Returns
    -------
    TensionResult
        Arrays with a leading axis of B poses for a batch (``success`` (B,) bool); for
        one pose ``(6,)`` or ``(3,)`` without it (``success`` a bool, ``tensions`` (m,)).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> res = distribute_tensions(robot, [[0, 0, 0.6], [0, 0, 2.2]], "qp_min_norm")
    >>> res.success.tolist(), res.status.tolist(), res.binding.tolist()
    ([True, False], ['ok', 'infeasible'], ['', 'limits'])
    >>> bool((robot.t_min <= res.tensions[0]).all()), bool(res.residual[0] < 1e-9)
    (True, True)
    >>> one = distribute_tensions(robot, [0, 0, 1.2])    # one pose
    >>> one.success, one.binding, one.tensions.shape
    (False, 'tipping', (8,))
    >>> one.message
    'not wrench-feasible: mobile bases active, passive tip over with the closed_form tensions (largest edge moment 87.85 N m)'
    """
    as_choice(method, METHODS, "method")
    as_choice(qp_solver, get_args(QPSolver), "qp_solver")
    tipping = as_flag(tipping, "tipping")
    sliding = as_flag(sliding, "sliding")
    single = is_single(poses)
    P = as_poses(robot, poses)
    st = cable_state(robot, P, validated=True)
    w = required_wrench(robot, st, external_wrench)
    use_tip = bool(tipping and robot.has_tipping)
    use_slide = bool(sliding and robot.has_sliding)
    sol = _solve(robot, st, w, method, qp_solver, use_tip, use_slide)
    feas = sol.success
    binding = _binding(robot, st, w, method, qp_solver, use_tip, use_slide, sol)
    names = ["tension"] + (["tipping"] if use_tip else []) + (["sliding"] if use_slide else [])
    what = " and ".join([", ".join(names[:-1]), names[-1]]) if len(names) > 1 else names[0]
    status, message = batch_outcome(feas, "infeasible", f"poses balanced within the {what} "
                                    "limits")
    if single:
        message = _pose_message(robot, method, use_tip, use_slide, sol, str(binding[0]))
    out = TensionResult(tensions=sol.tensions, success=feas, status=status, message=message,
                        binding=binding, within_limits=sol.within, residual=sol.residual,
                        tipping_moments=sol.tipping_moments, method=method, tipping=use_tip,
                        sliding=use_slide)
    return unbatch(out, ("tensions", "success", "status", "binding", "within_limits",
                         "residual", "tipping_moments"), single)


def _solve(robot: CableRobot, st: CableState, w: np.ndarray, method: str, qp_solver: str,
           use_tip: bool, use_slide: bool) -> _Solved:
    """Tensions by ``method`` under the tension limits (and tipping, sliding rows), polished
    onto ``W t = w``, with the conditions they meet."""
    B = st.W.shape[0]
    A, b = constraints(robot, st, use_tip, use_slide)
    if method == "closed_form":
        pinv, ok = None, np.ones(B, dtype=bool)             # rank judged by the residual
        t = _closed_form(robot, st.W, w, ok)
    else:
        pinv, N, ok = svd_split(st.W)
        r = robot.m - robot.dof
        if method.startswith("lp_"):
            t = _lp(st.W, w, A, b, robot, minmax=(method == "lp_min_max"))
        elif qp_solver in ("scipy", "daqp") or (qp_solver == "auto" and r > 2):
            t = _qp_per_pose(st.W, w, A, b, robot, qp_backend(
                "auto" if qp_solver == "auto" else qp_solver))
        elif r > 2:
            raise InvalidInputError("qp_solver", "enumeration needs at most 2 redundant "
                                                 "cables; use qp_solver='daqp' or 'scipy'")
        else:
            t = np.concatenate([_qp_enum(pinv[c], N[c], w[c], A[c], b[c], ok[c], robot)
                                for c in _chunks(B, 512)]) if B else np.zeros((0, robot.m))
    found = np.all(np.isfinite(t), axis=1)
    # Polish: minimum-norm correction onto W t = w (removes solver round-off).
    tz = np.where(found[:, None], t, 0.0)
    tz = np.where(ok[:, None], tz + _min_norm_correction(st.W, pinv, w, tz), tz)
    res = np.abs(np.einsum("bij,bj->bi", st.W, tz) - w).max(axis=1)
    tip_m = (np.einsum("bji,bi->bj", tipping_matrix(robot, st.unit), tz)
             + robot.edge_weight_moment)
    tol = feas_tol(robot)
    wscale = 1.0 + np.abs(w).max(axis=1)
    rows = np.einsum("bkm,bm->bk", A, tz) <= b + tol        # bounds, tipping, sliding rows
    m, k_tip = robot.m, 2 * robot.m + (robot.n_edges if use_tip else 0)
    within = (rows[:, :m] & rows[:, m:2 * m]) & found[:, None]
    limits = found & ok & (res <= RESIDUAL_REL * wscale) & within.all(axis=1)
    tips = (~rows[:, 2 * m:k_tip] | (tip_m > tol)) if use_tip else np.zeros((B, 0), bool)
    slide_base = sliding_rows(robot, st.unit[:1])[2] if use_slide else np.zeros(0, np.intp)
    return _Solved(tensions=np.where(found[:, None], tz, np.nan), found=found,
                   residual=np.where(found, res, np.nan),
                   tipping_moments=np.where(found[:, None], tip_m, np.nan), within=within,
                   limits=limits, tips=tips & found[:, None],
                   slides=~rows[:, k_tip:] & found[:, None], slide_base=slide_base)


def _subset(st: CableState, idx: np.ndarray) -> CableState:
    return CableState(*(getattr(st, f.name)[idx] for f in fields(CableState)))


def _binding(robot: CableRobot, st: CableState, w: np.ndarray, method: str, qp_solver: str,
             use_tip: bool, use_slide: bool, sol: _Solved) -> np.ndarray:
    """Per pose the first condition (limits, tipping, sliding) that fails (see
    :class:`TensionResult`); poses without tensions are solved again without the later
    conditions to tell which one leaves no solution."""
    binding = np.where(sol.success, "", np.where(
        ~sol.limits, "limits", np.where(sol.tips.any(axis=1), "tipping", "sliding")))
    none = np.nonzero(~sol.found)[0]
    if none.size and (use_tip or use_slide):
        lim = _solve(robot, _subset(st, none), w[none], method, qp_solver, False, False)
        held = none[lim.success]
        binding[held] = "tipping" if use_tip else "sliding"
        if use_tip and use_slide and held.size:
            tip = _solve(robot, _subset(st, held), w[held], method, qp_solver, True, False)
            binding[held[tip.success]] = "sliding"
    return binding.astype(str)


def _names(robot: CableRobot, bases: np.ndarray) -> str:
    return ", ".join(robot.bases[int(k)].name for k in np.unique(bases))


def _pose_message(robot: CableRobot, method: str, use_tip: bool, use_slide: bool,
                  sol: _Solved, binding: str) -> str:
    """The one-line answer for one pose: wrench-feasible or not, and why."""
    if binding == "":
        return ("wrench-feasible: tensions within the cable limits"
                + (", no mobile base tips" if use_tip else "")
                + (", no mobile base slides" if use_slide else "")
                + (" (tipping not considered)" if robot.has_tipping and not use_tip else ""))
    head = "not wrench-feasible: "
    found = bool(sol.found[0])
    if binding == "limits":
        if method == "closed_form" and found:
            return head + ("the closed_form tensions leave the cable limits (the closed form "
                           "is conservative; an LP or QP method may still find tensions)")
        return head + "no tensions within the cable limits balance the platform"
    if binding == "tipping":
        if not found:
            return head + "every tension distribution within the cable limits tips a mobile base"
        tips = sol.tips[0]
        k = np.unique(robot.edge_base[tips])
        return head + (f"mobile base{'s' if len(k) > 1 else ''} {_names(robot, k)} "
                       f"tip{'' if len(k) > 1 else 's'} over with the {method} tensions "
                       f"(largest edge moment {np.max(sol.tipping_moments[0]):.2f} N m)")
    if not found:
        return head + ("every tension distribution within the cable limits"
                       + (" and the tipping limits" if use_tip else "") + " slides a mobile base")
    k = np.unique(sol.slide_base[sol.slides[0]])
    return head + (f"mobile base{'s' if len(k) > 1 else ''} {_names(robot, k)} "
                   f"slide{'' if len(k) > 1 else 's'} with the {method} tensions")


def _chunks(n: int, size: int) -> list[slice]:
    return [slice(i, i + size) for i in range(0, n, size)]


def _min_norm_correction(W: np.ndarray, pinv: np.ndarray | None, w: np.ndarray,
                         t: np.ndarray) -> np.ndarray:
    """``W+ (w - W t)``: the smallest change of ``t`` that restores ``W t = w``."""
    e = w - np.einsum("bij,bj->bi", W, t)
    if pinv is not None:
        return np.einsum("bij,bj->bi", pinv, e)
    try:
        y = np.linalg.solve(W @ np.swapaxes(W, 1, 2), e[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.einsum("bij,bj->bi", np.linalg.pinv(W), e)
    return np.einsum("bij,bi->bj", W, y)


def _closed_form(robot: CableRobot, W: np.ndarray, w: np.ndarray, ok: np.ndarray
                 ) -> np.ndarray:
    """Pott's improved closed-form method, batched (see module docstring)."""
    B, n, m = W.shape
    lo, hi = robot.t_min, robot.t_max
    tm = 0.5 * (lo + hi)
    free = np.ones((B, m), dtype=bool)
    fixed = np.zeros((B, m))
    active = ok.copy()
    t = np.tile(tm, (B, 1))
    tol = feas_tol(robot)
    for _ in range(m - n + 1):
        if not np.any(active):
            break
        idx = np.nonzero(active)[0]
        Wa = W[idx]
        fr = free[idx]
        base = np.where(fr, tm, fixed[idx])
        rhs = w[idx] - np.einsum("bij,bj->bi", Wa, base)
        Wf = Wa * fr[:, None, :]
        M = Wf @ np.swapaxes(Wf, 1, 2)
        try:
            y = np.linalg.solve(M, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            y = np.einsum("bij,bj->bi", np.linalg.pinv(M), rhs)
        ta = base + np.einsum("bij,bi->bj", Wf, y)
        t[idx] = ta
        viol = np.maximum(lo - ta, ta - hi)
        bad = viol.max(axis=1) > tol
        can = fr.sum(axis=1) > n
        go = bad & can
        if not np.any(go):
            break
        gi = idx[go]
        j = np.argmax(np.where(fr[go], viol[go], -np.inf), axis=1)
        tj = ta[go, j]
        fixed[gi, j] = np.where(tj < lo[j], lo[j], hi[j])
        free[gi, j] = False
        active[:] = False
        active[gi] = True
    return t


def _lp(W: np.ndarray, w: np.ndarray, A: np.ndarray, b: np.ndarray, robot: CableRobot,
        minmax: bool) -> np.ndarray:
    """Per-pose HiGHS LPs: minimum sum, or minimum maximum (epigraph variable)."""
    B, n, m = W.shape
    out = np.full((B, m), np.nan)
    extra = A[:, 2 * m:, :]
    bx = list(zip(robot.t_min, robot.t_max))
    for k in range(B):
        if minmax:
            c = np.r_[np.zeros(m), 1.0]
            Aeq = np.hstack([W[k], np.zeros((n, 1))])
            Aub = np.vstack([np.hstack([np.eye(m), -np.ones((m, 1))]),
                             np.hstack([extra[k], np.zeros((extra.shape[1], 1))])])
            bub = np.r_[np.zeros(m), b[k, 2 * m:]]
            bounds = bx + [(0.0, None)]
        else:
            c = np.ones(m)
            Aeq = W[k]
            Aub = extra[k] if extra.shape[1] else None  # type: ignore[assignment]
            bub = b[k, 2 * m:] if extra.shape[1] else None
            bounds = bx
        sol = linprog(c, A_ub=Aub, b_ub=bub, A_eq=Aeq, b_eq=w[k], bounds=bounds,
                      method="highs")
        if sol.status == 0:
            out[k] = sol.x[:m]
    return out


def _qp_enum(pinv: np.ndarray, N: np.ndarray, w: np.ndarray, A: np.ndarray, b: np.ndarray,
             ok: np.ndarray, robot: CableRobot) -> np.ndarray:
    """Exact batched min-norm QP for r = m - n <= 2 redundant cables (KKT enumeration)."""
    B, m, r = N.shape
    tp = np.einsum("bij,bj->bi", pinv, w)
    G = np.einsum("bkm,bmr->bkr", A, N)                      # constraints G z <= h
    h = b - np.einsum("bkm,bm->bk", A, tp)
    K = G.shape[1]
    cands = [np.zeros((B, 1, r))]
    if r >= 1:
        gg = np.einsum("bkr,bkr->bk", G, G)
        safe = np.where(gg > QP_ROW_SQ, gg, np.inf)
        cands.append(G * (h / safe)[..., None])             # feet on each constraint line
    if r == 2:
        i, j = np.array(list(combinations(range(K), 2))).T
        gi, gj = G[:, i, :], G[:, j, :]
        det = gi[..., 0] * gj[..., 1] - gi[..., 1] * gj[..., 0]
        sd = np.where(np.abs(det) > QP_PARALLEL, det, np.nan)
        hi_, hj = h[:, i], h[:, j]
        z0 = (hi_ * gj[..., 1] - hj * gi[..., 1]) / sd
        z1 = (gi[..., 0] * hj - gj[..., 0] * hi_) / sd
        cands.append(np.stack([z0, z1], axis=-1))           # vertices
    Z = np.concatenate(cands, axis=1) if r else np.zeros((B, 1, 0))
    tol = feas_tol(robot)
    with np.errstate(invalid="ignore"):
        viol = np.einsum("bkr,bcr->bck", G, Z) - h[:, None, :]
        feas = np.all(viol <= tol, axis=2) & np.all(np.isfinite(Z), axis=2)
    cost = np.where(feas, np.einsum("bcr,bcr->bc", Z, Z), np.inf)
    best = np.argmin(cost, axis=1)
    zb = Z[np.arange(B), best]
    t = tp + np.einsum("bmr,br->bm", N, zb)
    found = np.isfinite(cost[np.arange(B), best]) & ok
    return np.where(found[:, None], t, np.nan)


def _qp_per_pose(W: np.ndarray, w: np.ndarray, A: np.ndarray, b: np.ndarray,
                 robot: CableRobot, backend: str) -> np.ndarray:
    """Per-pose min-norm QP by :func:`taut._qp.solve_qp` (DAQP, or SLSQP from the mean
    tension), each answer checked against the constraint rows."""
    B, n, m = W.shape
    out = np.full((B, m), np.nan)
    tm = 0.5 * (robot.t_min + robot.t_max)
    slack = SLSQP_REL * float(np.max(robot.t_max))
    eye = np.eye(m)
    for k in range(B):
        x = solve_qp(eye, A_eq=W[k], b_eq=w[k], A_ub=A[k], b_ub=b[k], x0=tm,
                     ftol=SLSQP_FTOL, backend=backend)
        if x is not None and np.all(A[k] @ x <= b[k] + slack):
            out[k] = x
    return out
