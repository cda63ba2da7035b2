"""The numpy solve of sheet forward kinematics: candidate taut sets, their Lagrange
systems, the paper's checks and the classification, batched over formations.

Works in the normalised frame of :class:`taut.sheet._lifted.Frame` and returns the
classified solutions (:class:`~taut.sheet.fk._finalize.Classified`); building result
objects is left to the engines (:mod:`taut.sheet.fk._numpy`, :mod:`taut.sheet.fk.solver`).
Candidates by method:

``"fast"``
    The upper convex hull of the lifted points (Qhull), with stationary points read off
    the facet normals for large teams (docs/sheet_kinematics.md §2); teams of at most
    ``SMALL_TEAM`` robots take every small subset instead (as ``"subsets"``).
``"exhaustive"``
    The FK paper's Algorithm 1 as published (:mod:`taut.sheet.fk.exhaustive`).
``"subsets"``
    Every set of at most 5 cables (complete, O(N^5)).
"""

from __future__ import annotations

from dataclasses import fields
from typing import Iterable

import numpy as np

from ._candidates import Stationary, hull_candidates, padded_small_subsets
from ._finalize import Classified, classify
from .._lifted import (KIND_STABLE, Frame, Solved, height_ok, in_hull_2d, maximiser_masks,
    pad_groups, solve_candidates, solve_table)
from ._similar import similar_copy
from .._tol import SNAP_MIN, SNAP_TOL
from .exhaustive import exhaustive_search
from ..model import Sheet

__all__ = ["solve", "explain_no_equilibrium", "SMALL_TEAM", "SHORTCUT_ABOVE"]

#: Up to this many robots every small subset is the candidate set (N = 12: 1,507
#: candidates), as in the compiled kernel (``solver.COMPILED_MAX_N``): both backends
#: then try the same candidates. Complete, and unlike the hull it needs no decision on
#: (nearly) degenerate lifted points -- near a similar copy, with (nearly) collinear or
#: coincident robots the numpy hull path missed states the subsets find.
SMALL_TEAM = 12
#: Above this many robots the hull path may read stationary points off the facet normals
#: (``_candidates._stationary_from_normals``). Up to it (``solver.KERNEL_MAX_N``) the
#: compiled kernel handles the team and solves every upper-hull face by the Lagrange
#: system; the numpy path does the same there, so the two backends try the same
#: candidates (on teams with nearly coincident robots the shortcut reported other
#: non-equilibria than the kernel).
SHORTCUT_ABOVE = 30
#: Candidate systems solved per block when every formation shares one candidate table.
TABLE_BLOCK = 65_536
#: Hull candidates: run the maximiser scan before the projection test when it touches at
#: most this many (candidate, cable) pairs (it is then cheaper than the projection test).
SCAN_FIRST = 20_000


def _candidates(frame: Frame, sheet: Sheet, method: str
                ) -> tuple[tuple[np.ndarray, np.ndarray] | np.ndarray | None, bool,
                           Stationary | None]:
    """Candidate taut sets of every formation for the Lagrange solver (with its
    ``independent`` flag): ``(form, subset)``, or one ``subset`` table shared by every
    formation; and hull-derived stationary points (generic formations)."""
    B, N = frame.b.shape
    pairs = sheet.has_collinear_vertices
    if method == "subsets" or N <= SMALL_TEAM:
        return padded_small_subsets(N, pairs), False, None
    per_size: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    independent = True
    stationary: list[Stationary] = []
    for b in range(B):
        hc = hull_candidates(frame.P[b], pairs, shortcut=N > SHORTCUT_ABOVE)
        if hc.stationary is not None:
            hc.stationary.form[:] = b
            stationary.append(hc.stationary)
        if hc.subsets:
            # Up to SHORTCUT_ABOVE the kernel screens every system; so does this path.
            independent &= hc.independent and N > SHORTCUT_ABOVE
        for s, idx in hc.subsets.items():
            per_size.setdefault(s, []).append((np.full(len(idx), b, dtype=np.intp), idx))
    groups = {s: (np.concatenate([f for f, _ in parts]), np.vstack([i for _, i in parts]))
              for s, parts in per_size.items()}
    merged = None
    if len(stationary) == 1:
        merged = stationary[0]
    elif stationary:
        merged = Stationary(*(np.concatenate([getattr(p, f) for p in stationary])
                              for f in Stationary.FIELDS))
    return (pad_groups(groups) if groups else None), independent, merged


def solve(sheet: Sheet, R: np.ndarray, hold_height: float, method: str
          ) -> tuple[Frame, Classified, dict[str, int] | None]:
    """Every rest state of formations ``R`` (B, N, 2) (validated) of ``sheet`` held at
    ``hold_height``: the normalised frame, the classified solutions in output order, and
    the step counts of Algorithm 1 (``method="exhaustive"`` only, else None). Formations
    next to a similar copy of the sheet are solved as the copy (``_snap_near_similar``), by
    every method: the exhaustive one too (issue 25: all methods report the same states),
    its step counts staying those of the formation as given."""
    frame, c, counts = _solve_as_given(sheet, R, hold_height, method)
    c = _snap_near_similar(sheet, R, hold_height, method, c)
    return frame, c, counts


def _snap_near_similar(sheet: Sheet, R: np.ndarray, hold_height: float, method: str,
                       c: Classified) -> Classified:
    """Formations within ``SNAP_TOL`` (relative) of a similar copy of the sheet, but not
    exactly one: solve the copy instead (when the copy has a stable state).

    Such formations are within float64 resolution of the FK paper's Lemma 2
    configuration (lifted points on a 2-plane): the rest state's taut set is decided by a
    thickness of ~1e-10, its 4- and 5-cable systems are numerically singular, the
    candidates can miss it, and where they find it they name one physical state by many
    taut sets (objects within ~1e-8 of each other; docs/sheet_fk_solver.md, "Next to a
    similar copy"). The copy is solved exactly (every cable taut at the Lemma 2 point,
    minimum-norm non-negative load shares); every method and backend gives that one
    answer. Positions move by about the snap distance, below ``SNAP_TOL`` times the sheet
    size.
    """
    B = R.shape[0]
    todo = np.arange(B)
    copies, scale, dist = similar_copy(sheet.vertices, R)
    near = ((dist > SNAP_MIN * sheet.size) & (dist <= SNAP_TOL * sheet.size)
            & (scale <= 1.0))
    if not near.any():
        return c
    todo, copies = todo[near], copies[near]
    _, c2, _ = _solve_as_given(sheet, copies, hold_height, method)
    replaced = np.zeros(B, dtype=bool)
    replaced[todo[np.unique(c2.form[c2.kind == KIND_STABLE])]] = True
    if not replaced.any():
        return c
    take2 = replaced[todo[c2.form]]
    keep = ~replaced[c.form]
    form = np.concatenate([c.form[keep], todo[c2.form[take2]]])
    order = np.argsort(form, kind="stable")
    merged = {f.name: np.concatenate([getattr(c, f.name)[keep], getattr(c2, f.name)[take2]])
              for f in fields(Classified) if f.name != "form"}
    return Classified(form=form[order], **{k: v[order] for k, v in merged.items()})


def _solve_as_given(sheet: Sheet, R: np.ndarray, hold_height: float, method: str
                    ) -> tuple[Frame, Classified, dict[str, int] | None]:
    frame = Frame.build(sheet.vertices, R, hold_height, sheet.size)
    if method == "exhaustive":
        solved, taut, counts = exhaustive_search(frame)
        return frame, classify(frame, solved, taut), counts
    groups, independent, stationary = _candidates(frame, sheet, method)
    # Rows from the Lagrange solver first, then (hull path) those from the normals, which
    # carry projection-test and curvature results (``None``: nothing known yet).
    parts: list[Solved] = []
    tauts: list[np.ndarray] = []
    N = frame.R.shape[1]
    if groups is not None:
        chunks: Iterable[Solved]
        if isinstance(groups, tuple):
            chunks = [solve_candidates(frame, *groups, independent=independent)]
        else:
            # One table for all formations: solve in cache-sized blocks of formations.
            step = max(1, TABLE_BLOCK // len(groups))
            chunks = (solve_table(frame, groups, slice(b, b + step), independent=independent)
                      for b in range(0, frame.b.shape[0], step))
        for solved in chunks:
            keep = np.flatnonzero(height_ok(frame, solved.depth2))
            ok, taut = maximiser_masks(frame, solved.form[keep], solved.x[keep],
                                       solved.mu[keep])
            parts.append(solved.take(keep[ok]))
            tauts.append(taut[ok])
    done = curv = None
    if stationary is not None:
        # Points already known: filter first, then solve only the survivors for weights.
        # Generic hull: a face's exact taut set is its own vertex set, so the paper's
        # projection test on the face is final for most rows. Cheapest test first: the
        # maximiser scan costs O(N) per row, the projection test O(1) but more calls.
        st = stationary
        keep = np.flatnonzero(height_ok(frame, st.depth2))
        scan_first = len(keep) * N <= SCAN_FIRST
        if scan_first:
            ok, taut = maximiser_masks(frame, st.form[keep], st.x[keep], st.mu[keep])
            keep, taut = keep[ok], taut[ok]
        sub = st.subset[keep]
        inside = in_hull_2d(frame.R[st.form[keep, None], np.maximum(sub, 0)], sub >= 0,
                            st.x[keep, :2])
        keep = keep[inside]
        if scan_first:
            taut = taut[inside]
        else:
            ok, taut = maximiser_masks(frame, st.form[keep], st.x[keep], st.mu[keep])
            keep, taut = keep[ok], taut[ok]
        sv = solve_candidates(frame, st.form[keep], st.subset[keep])
        taut = taut[sv.source]
        before = sum(len(t) for t in tauts)
        done = np.concatenate([np.zeros(before, dtype=bool), taut.sum(axis=1) == sv.size])
        curv = np.concatenate([np.full(before, np.nan), st.curvature[keep[sv.source]]])
        parts.append(sv)
        tauts.append(taut)
    solved = Solved.concat(parts)
    taut = tauts[0] if len(tauts) == 1 else (
        np.vstack(tauts) if tauts else np.zeros((0, N), dtype=bool))
    return frame, classify(frame, solved, taut, done, curv), None


def explain_no_equilibrium(sheet: Sheet, formation: np.ndarray, hold_height: float) -> str:
    """Why forward kinematics finds no state for ``formation`` (N, 2) (validated): the
    rest states the object would reach if the floor were not there.

    The team is solved with its holding points raised by the sheet's diameter (an upper
    bound of every cable length): the depth of a state below the holding points does not
    depend on the hold height, and the FK paper's eq. 15 only discards the states with
    :math:`z_o \\le 0`. Returns one line (no trailing period), naming up to five such
    states with their (negative) object heights :math:`z_o` at the actual hold height.
    """
    v = sheet.vertices
    diameter = float(max(((v[:, None] - v[None]) ** 2).sum(-1).max() ** 0.5, 1.0))
    frame, c, _ = solve(sheet, np.asarray(formation, dtype=np.float64)[None],
                        hold_height + diameter, "fast")
    z = hold_height - c.depth * frame.scale
    below = np.flatnonzero(z <= 0)
    if not len(below):
        return "no state of this team passes the paper's Algorithm 1"
    parts = ", ".join("{" + ",".join(str(i + 1) for i in np.flatnonzero(c.taut[k])) + "}"
                      f" at z_o = {z[k]:.4g}" for k in below[:5])
    more = f" and {len(below) - 5} more" if len(below) > 5 else ""
    return (f"{len(below)} state(s) discarded because the object would hang at or below the "
            f"floor (z_o <= 0, FK paper eq. 15): {parts}{more}; raise the hold height or "
            "spread the robots apart (a tighter sheet holds the object higher)")
