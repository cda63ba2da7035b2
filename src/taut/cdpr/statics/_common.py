"""Shared linear-algebra pieces of the CDPR statics (private)."""

from __future__ import annotations

from functools import lru_cache
from itertools import combinations
from typing import Any

import numpy as np

from ..._outcome import check_status
from ..._validate import MAX_CDPR_LENGTH_M, MAX_TENSION_N, as_array, check_range
from ...errors import InvalidInputError
from ..kinematics.cables import CableState, gravity_wrench, tipping_matrix
from .._tol import FEAS_REL, RANK_TOL
from ..model.robot import CableRobot
from .sliding import sliding_rows

#: Largest |component| of an external wrench, N or N m (the largest tension limit times the
#: largest cable-robot length: far beyond any cable's reach, far from float64 overflow).
MAX_WRENCH = MAX_TENSION_N * MAX_CDPR_LENGTH_M


@lru_cache(maxsize=64)
def subsets(K: int, s: int) -> np.ndarray:
    """Every ``s``-subset of ``range(K)`` in lexicographic order, as an (C, s) index array
    (one row, zero columns for ``s = 0``). Cached: the tables are reused for every batch."""
    if s == 0:
        return np.zeros((1, 0), dtype=np.intp)
    return np.array(list(combinations(range(K), s)), dtype=np.intp).reshape(-1, s)


def svd_split(W: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pseudo-inverse ``W+`` (B, m, n), orthonormal null-space basis ``N`` (B, m, m-n) and a
    full-rank flag (B,) of a batch of wrench matrices W (B, n, m)."""
    B, n, m = W.shape
    U, S, Vt = np.linalg.svd(W, full_matrices=True)
    ok = S[:, -1] > RANK_TOL * S[:, 0]
    inv = np.where(ok[:, None], 1.0 / np.where(S > 0, S, 1.0), 0.0)
    pinv = np.einsum("bki,bk,bjk->bij", Vt[:, :n, :], inv, U)
    N = np.swapaxes(Vt[:, n:, :], 1, 2)
    return pinv, N, ok


def required_wrench(robot: CableRobot, state: CableState, external: Any = None,
                    field: str = "external_wrench") -> np.ndarray:
    """The wrench the cables must apply, ``-(w_e + w_ext)`` (B, n) (FASTKIT eqs. 17, 19)."""
    w = gravity_wrench(robot, state.R)
    if external is not None:
        ext = check_range(external, field, MAX_WRENCH, "N or N m")
        if (ext.ndim not in (1, 2) or ext.shape[-1] != robot.dof
                or (ext.ndim == 2 and ext.shape[0] not in (1, w.shape[0]))):
            raise InvalidInputError(field, f"must have {robot.dof} components (forces, N"
                                           + (", then moments, N m)" if robot.dof == 6 else ")"))
        w = w + ext
    return -w


def constraints(robot: CableRobot, state: CableState, tipping: bool, sliding: bool = False
                ) -> tuple[np.ndarray, np.ndarray]:
    """Linear constraints ``A t <= b`` on tensions: the bounds of FASTKIT eq. 20, when
    ``tipping`` the edge moments of eqs. 21-23, and when ``sliding`` the friction pyramids
    of :mod:`taut.cdpr.statics.sliding` (bases with a friction coefficient only). Returns A
    (B, K, m) and b (B, K); rows in that order (bounds first: 2 m rows)."""
    B, m = state.lengths.shape
    eye = np.eye(m)
    rows = [eye, -eye]
    rhs = [robot.t_max, -robot.t_min]
    A = np.broadcast_to(np.concatenate(rows)[None], (B, 2 * m, m))
    b = np.broadcast_to(np.concatenate(rhs)[None], (B, 2 * m))
    if tipping and robot.has_tipping:
        T = tipping_matrix(robot, state.unit)
        A = np.concatenate([A, T], axis=1)
        b = np.concatenate([b, np.broadcast_to(-robot.edge_weight_moment, (B, robot.n_edges))],
                           axis=1)
    if sliding and robot.has_sliding:
        S, s, _ = sliding_rows(robot, state.unit)
        A = np.concatenate([A, S], axis=1)
        b = np.concatenate([b, np.broadcast_to(s, (B, len(s)))], axis=1)
    return A, b


def feas_tol(robot: CableRobot) -> float:
    """Absolute tolerance on tensions and moments, scaled by the largest tension limit."""
    return FEAS_REL * float(np.max(robot.t_max))


def batch_outcome(success: np.ndarray, failure: str, what: str) -> tuple[np.ndarray, str]:
    """Status array (B,) (``"ok"`` where ``success`` else ``failure``, a value of
    :data:`taut._outcome.STATUSES`) and a one-line message ``"k of B <what>"``."""
    check_status(failure)
    ok = np.asarray(success, dtype=bool)
    status = np.where(ok, "ok", failure)
    return status, f"{int(ok.sum())} of {ok.size} {what}"



def wrench_vertices(robot: CableRobot, external_wrench: Any, field: str = "external_wrench"
                    ) -> np.ndarray:
    """Extra external wrenches as vertices (V, n) (default one zero wrench); one wrench
    (n,) is one vertex."""
    if external_wrench is None:
        return np.zeros((1, robot.dof))
    D = check_range(external_wrench, field, MAX_WRENCH, "N or N m")
    D = D[None, :] if D.ndim == 1 else D
    if D.ndim != 2 or D.shape[1] != robot.dof or D.shape[0] == 0:
        raise InvalidInputError(field, f"must be (V, {robot.dof}) vertices of extra "
                                       "external wrenches (N, N m)")
    return D
