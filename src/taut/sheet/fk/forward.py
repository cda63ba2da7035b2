"""Forward kinematics of an N-robot team holding a deformable sheet (VVCM).

Given the sheet, the robots' planar positions and their common holding height, find every
place the object can rest (FK paper: Hu, Liu, Yi, Xiong, "Forward Kinematics of Object
Transport by a Multi-Robot System with Deformable Sheet", Algorithm 1), classify each as
stable, saddle or not an equilibrium, and give each taut cable's share of the load.

This is the front end: it validates the inputs and dispatches to an engine -- the compiled
solver (:class:`taut.sheet.FKSolver`, numba) or the numpy engine
(:mod:`taut.sheet.fk._numpy` over :mod:`taut.sheet.fk._solve`; the exhaustive search of
:mod:`taut.sheet.fk.exhaustive`). The engines never import this module.

Methods (one interface, chosen by ``method``):

``"fast"`` (default)
    Candidate taut sets from the upper convex hull of the lifted points (Qhull), their
    stationary points read off the facet normals (docs/sheet_kinematics.md §2). Same solutions as
    Algorithm 1; O(N^2) candidates. Teams of at most ``_solve.SMALL_TEAM`` robots take every
    small subset instead (as ``"subsets"``), one cached table solved for all formations
    at once, which is cheaper there.
``"exhaustive"``
    Algorithm 1 as published: all :math:`\\sum_{k\\ge3}\\binom{N}{k}` taut sets, the rank
    test (eq. 5), the Lagrange solution (eqs. 10-15), the slack and height checks and the
    projection force-closure test, with the step counts of Tables II and IV.
``"subsets"``
    Every set of at most 5 cables as a candidate (complete, O(N^5)); a cross-check of
    ``"fast"`` that needs no convex hull.

One formation at a time, a process answers with the numpy engine until its FK calls have
taken as long as loading the compiled kernels would (:func:`taut._jit.prefer_compiled`:
a one-shot ``taut fk`` never loads numba), then with the compiled solver; both give the
same equilibria.
"""

from __future__ import annotations

import time

from numpy.typing import ArrayLike

from ..._jit import charge_numpy, prefer_compiled
from ..._validate import as_choice
from ...errors import InvalidInputError
from ._numpy import forward_numpy
from .._options import METHODS, Method
from .results import BatchFKResult, FKResult
from .solver import cached_solver
from ..team import SheetTeam, require_team

__all__ = ["forward_kinematics", "forward_kinematics_batch"]


def forward_kinematics(team: SheetTeam, formation: ArrayLike, *, method: Method = "fast"
                       ) -> FKResult:
    """Every rest state of the object for one robot formation.

    Parameters
    ----------
    team : SheetTeam
        The sheet (vertices :math:`\\mathcal{V}_N^0` in the sheet frame), the height
        :math:`z_r` of all holding points above the ground and, optionally, the object
        mass in kg; with a mass, each equilibrium's cable tensions are reported in N
        (g = 9.81 m/s^2). The formula :math:`F_i = w_i m g L_i / d` (FK paper eq. 16
        solved with the weights) uses only a ratio of lengths, so any length unit works.
    formation : array_like, shape (N, 2)
        Robot positions :math:`\\mathcal{R}_N` in the world frame, robot ``i`` holding
        sheet vertex ``i``. Same length unit as the sheet.
    method : {"fast", "exhaustive", "subsets"}
        Algorithm (see module docstring). All return the same stable states. Within
        ``SNAP_TOL`` (1e-7 of the sheet size) of a similar copy of the sheet (the FK
        paper's Lemma 2 configuration), where float64 cannot resolve the taut set,
        every method solves the copy (docs/sheet_fk_solver.md). Every method
        reports one physical state once: states whose object and contact points
        coincide within ``MERGE_RTOL`` (1e-5 of the sheet size) are merged into one on
        the union of their taut cables; and where no stable state was enumerated, a
        direct minimisation of the height supplies the lowest rest state (``.direct``)
        or says why there is none (the floor, or the object slides off the sheet).

    Returns
    -------
    FKResult
        ``.equilibria`` (every state passing the paper's Algorithm 1, each with ``taut``,
        ``object``, ``contact``, ``weights``, ``tensions``, ``kind``, ``stable``),
        ``.stable``, ``.lowest`` (the lowest rest state), ``.direct`` (the direct
        minimisation supplied it), ``.funnel`` for the exhaustive method, and the
        outcome: ``.success`` (at least one stable state), ``.status`` (``"ok"``;
        ``"not_strict"``: the lowest rest state is not a strict minimum, reported as a
        ``"saddle"``; ``"infeasible"``), ``.message`` (without any state, why: e.g. the
        states that would hang below the floor).

    Raises
    ------
    InvalidInputError
        ``team`` not a :class:`SheetTeam`, bad shapes, NaN/inf, robot count different
        from the sheet's, unknown method, exhaustive search too large,
        ``"subsets"`` for more than ``SUBSETS_MAX_ROBOTS`` (40) robots.
    InfeasibleFormationError
        Two robots farther apart than their sheet vertices (paper's FormationFeasible).

    Examples
    --------
    A unit square sheet held by robots on a square of side 0.9 at height 1: the object
    hangs below the centre on all four cables, each as long as the sheet's half-diagonal.

    >>> import taut.sheet as ts
    >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0, mass=2.0)
    >>> res = ts.forward_kinematics(team, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
    >>> e = res.lowest
    >>> e.taut, e.kind, [round(float(c), 4) for c in e.object]
    ((0, 1, 2, 3), 'stable', [0.45, 0.45, 0.6918])
    >>> [round(float(w), 3) for w in e.weights]     # equal load shares
    [0.25, 0.25, 0.25, 0.25]
    >>> res.success, res.status, res.message
    (True, 'ok', '1 solution(s), 1 stable')

    Notes
    -----
    The object is a point mass; the sheet inelastic and perfectly flexible; cable ``i``
    is the segment from holding point :math:`(\\mathbf{r}_i, z_r)` to the object with
    length :math:`|\\mathbf{v}_i - \\mathbf{v}_o|` (eq. 1). Solutions require
    :math:`0 < z_o < z_r` (eq. 15: the object does not touch the ground at z = 0).
    """
    team = require_team(team)
    method = as_choice(method, METHODS, "method")  # type: ignore[assignment]
    if method == "exhaustive":
        return forward_numpy(team.sheet, formation, team.hold_height, team.mass, method)
    if prefer_compiled():
        return cached_solver(team, method).solve(formation)
    t0 = time.perf_counter()
    try:
        return cached_solver(team, method, "numpy").solve(formation)
    finally:
        charge_numpy(time.perf_counter() - t0)


def forward_kinematics_batch(team: SheetTeam, formations: ArrayLike, *,
                             method: Method = "fast") -> BatchFKResult:
    """Forward kinematics of many formations of one team at once.

    Parameters
    ----------
    team : SheetTeam
        As in :func:`forward_kinematics`.
    formations : array_like, shape (B, N, 2)
        ``B`` formations (same length unit as the sheet).
    method : {"fast", "subsets"}
        As in :func:`forward_kinematics` (``"exhaustive"`` has no batched form).

    Returns
    -------
    BatchFKResult
        Padded arrays with a leading batch axis; ``.result(b)`` gives an
        :class:`FKResult` for one formation. A formation the sheet cannot span does not
        stop the batch: its row has no solutions, ``feasible[b]`` and ``success[b]``
        False, ``status[b]`` ``"infeasible"``, and ``.message`` names the first one.

    Raises
    ------
    InvalidInputError
        ``team`` not a :class:`SheetTeam`, bad shapes, NaN/inf, robot count different
        from the sheet's, unknown method or ``"exhaustive"``.

    Examples
    --------
    >>> import taut.sheet as ts
    >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0)
    >>> v = team.sheet.vertices
    >>> b = ts.forward_kinematics_batch(team, [0.9 * v, 0.8 * v])
    >>> low = b.result(1).lowest
    >>> b.count.tolist(), low.taut, [round(float(c), 4) for c in low.object]
    ([1, 1], (0, 1, 2, 3), [0.4, 0.4, 0.5757])

    A formation that would tear the sheet is flagged; the others are answered:

    >>> b = ts.forward_kinematics_batch(team, [0.9 * v, 2.0 * v])
    >>> b.success.tolist(), b.status.tolist(), b.count.tolist()
    ([True, False], ['ok', 'infeasible'], [1, 0])
    """
    team = require_team(team)
    method = as_choice(method, METHODS, "method")  # type: ignore[assignment]
    if method == "exhaustive":
        raise InvalidInputError("method", "the batched form supports 'fast' and 'subsets'")
    return cached_solver(team, method).solve_batch(formations)
