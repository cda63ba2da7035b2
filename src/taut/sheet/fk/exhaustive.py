"""The FK paper's Algorithm 1, faithfully: every taut set of 3..N cables is tried.

Kept as the reference the fast method is checked against, and to reproduce the paper's
step counts (Tables II and IV). Vectorised per set size; still exponential in N.
"""

from __future__ import annotations

from math import comb

import numpy as np

from ...errors import InvalidInputError
from .._tol import ELIMINATION_RTOL
from .._util import combo_table
from .._lifted import Frame, Solved, height_ok, pad_groups, solve_candidates, taut_masks

#: Refuse exhaustive searches larger than this many taut-set combinations.
MAX_COMBINATIONS = 5_000_000


def count_combinations(N: int) -> int:
    """:math:`\\sum_{k=3}^{N} \\binom{N}{k}`, the number of sets Algorithm 1 visits."""
    return sum(comb(N, k) for k in range(3, N + 1))


def _independent_rows(A: np.ndarray) -> np.ndarray:
    """Greedy maximal linearly independent subset of the rows of each ``A[m]`` (M, r, 4),
    in row order (Gaussian elimination, FK paper eq. 10). Returns a bool mask (M, r)."""
    M, r, c = A.shape
    Q = np.zeros((M, c, c))
    count = np.zeros(M, dtype=np.intp)
    take = np.zeros((M, r), dtype=bool)
    scale = np.maximum(np.linalg.norm(A, axis=(1, 2)), 1.0)
    for j in range(r):
        v = A[:, j, :]
        res = v - np.einsum("mik,mi->mk", Q, np.einsum("mik,mk->mi", Q, v))
        norm = np.linalg.norm(res, axis=1)
        new = (norm > ELIMINATION_RTOL * scale) & (count < c)
        rows = np.flatnonzero(new)
        Q[rows, count[rows]] = res[rows] / norm[rows, None]
        count[rows] += 1
        take[:, j] = new
    return take


def exhaustive_search(frame: Frame) -> tuple[Solved, np.ndarray, dict[str, int]]:
    """Run Algorithm 1 on one formation (``frame`` with B = 1).

    Returns the solutions that pass step 3 (slack test and height), their taut masks
    (each equal to its combination), and the step counts so far.
    """
    N = frame.R.shape[1]
    total = count_combinations(N)
    if total > MAX_COMBINATIONS:
        raise InvalidInputError(
            "method", f"exhaustive search over N={N} robots would try {total:,} taut sets "
                      f"(limit {MAX_COMBINATIONS:,}); use method='fast'")
    P = frame.P[0]
    counts = {"combinations": total, "form_closure": 0, "cqp_feasible": 0, "height_feasible": 0}
    solved_parts: list[Solved] = []
    taut_parts: list[np.ndarray] = []
    for k in range(3, N + 1):
        combos = combo_table(N, k) if k <= 12 else _combos_uncached(N, k)
        # Paper eq. 4: rows i != i1 of [A1 | b1] (lifted-point differences, same rank).
        D = P[combos[:, 1:]] - P[combos[:, :1]]
        rank_A = np.linalg.matrix_rank(D[..., :4])
        rank_Ab = np.linalg.matrix_rank(D)
        fc = rank_A == rank_Ab                                      # eq. 5
        counts["form_closure"] += int(fc.sum())
        combos, D = combos[fc], D[fc]
        if len(combos) == 0:
            continue
        # Eq. 10: solve with a maximal independent subset of the equalities (plus i1).
        take = _independent_rows(D[..., :4])
        sizes = take.sum(axis=1) + 1
        for s in np.unique(sizes):
            if s < 2 or s > 5:
                continue
            own = np.flatnonzero(sizes == s)
            rows = np.hstack([np.zeros((len(own), 1), np.intp),
                              1 + np.nonzero(take[own])[1].reshape(len(own), s - 1)])
            subsets = np.take_along_axis(combos[own], rows, axis=1)
            sv = solve_candidates(frame, *pad_groups({int(s): (np.zeros(len(own), np.intp), subsets)}))
            own = own[sv.source]
            ok, taut = taut_masks(frame, sv)
            want = np.zeros((len(own), N), dtype=bool)
            want[np.arange(len(own))[:, None], combos[own]] = True
            slack_ok = ok & np.all(taut == want, axis=1)             # eq. 4: A2 x > b2
            counts["cqp_feasible"] += int(slack_ok.sum())
            h_ok = slack_ok & height_ok(frame, sv)                   # eq. 15, 0 < z_o < z_r
            counts["height_feasible"] += int(h_ok.sum())
            solved_parts.append(sv.take(h_ok))
            taut_parts.append(want[h_ok])
    solved = Solved.concat(solved_parts)
    taut = np.vstack(taut_parts) if taut_parts else np.zeros((0, N), dtype=bool)
    return solved, taut, counts


def _combos_uncached(N: int, k: int) -> np.ndarray:
    from itertools import combinations
    return np.array(list(combinations(range(N), k)), dtype=np.intp).reshape(-1, k)

