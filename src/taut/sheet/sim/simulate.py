"""Quasi-static transport simulation: what the object does while the robots move.

Model (FK paper Sec. II; docs/sheet_kinematics.md §1-§5). At every instant the object rests at a
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
lowest one); so it is too when the descent stops short of a stable state and the nearest
one lies above the start (a roll never raises the object). Tracking then continues to
the end of the step. Taut-set-change events are
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

Tracking runs over chunks of steps in one compiled call per chunk (``_step_kernel``,
numba; or one batched numpy solve per chunk without numba), so the cost per step is a few
microseconds; full FK is called only at events. The same tracker
(:mod:`._branch`) drives the stateful :class:`Simulator`, one step at a time, for control
loops (set robot velocities or formations, step, read the object).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_array, as_choice
from ...errors import InvalidInputError, InvalidTrajectoryError
from ._branch import (State, Tracker, fk_result, fk_stable_batch, from_equilibrium, make_event,
    members, nearest, resolve_step)
from ..._jit import HAVE_NUMBA, not_compiled_reason
from .results import EventKind, SimulationEvent, SimulationResult, SimulatorState
from .._options import BACKENDS, Backend
from ..model import Sheet, check_formations
from ..._units import GRAVITY
from ..team import SheetTeam, require_team

__all__ = ["simulate"]


def _compiled(backend: object) -> bool:
    """Whether ``backend`` selects the compiled branch follower (as ``FKSolver``'s
    ``backend``: ``"numba"`` without numba installed is an error)."""
    backend = as_choice(backend, BACKENDS, "backend")
    if backend == "numba" and not HAVE_NUMBA:
        raise InvalidInputError("backend", not_compiled_reason())
    return backend != "numpy" and HAVE_NUMBA


def _initial_state(team: SheetTeam, R: np.ndarray, start: object | None, field: str
                   ) -> State:
    """The stable state of formation R nearest to ``start`` (3,) (default: the lowest)."""
    fk0 = fk_result(team, R)
    if not fk0.stable:
        raise InvalidTrajectoryError(field, "no stable rest state for the object at step 0")
    if start is None:
        first = fk0.lowest
        assert first is not None
    else:
        p = as_array(start, "start", shape=(3,))
        first = min(fk0.stable, key=lambda e: float(np.linalg.norm(e.object - p)))
    return from_equilibrium(first, team.sheet, R, team.hold_height)


class _Record:
    """Per-step arrays of a simulation being filled in."""

    def __init__(self, T: int, N: int):
        self.obj = np.full((T, 3), np.nan)
        self.con = np.full((T, 2), np.nan)
        self.wts = np.zeros((T, N))
        self.taut = np.zeros((T, N), dtype=bool)

    def store(self, t: int, s: State | None) -> None:
        if s is None:
            return
        self.obj[t] = (*s.ro, s.z)
        self.con[t] = s.vo
        self.wts[t] = s.w
        self.taut[t, list(s.taut)] = True

    def store_branch(self, t: int, k: int, ro: np.ndarray, vo: np.ndarray, zo: np.ndarray,
                     w: np.ndarray, tight: np.ndarray) -> None:
        sl = slice(t, t + k)
        self.obj[sl, :2], self.obj[sl, 2], self.con[sl], self.wts[sl] = ro, zo, vo, w
        self.taut[sl] = tight


def _tensions(sheet: Sheet, z: float, mass: float | None, contact: np.ndarray,
              obj: np.ndarray, weights: np.ndarray, taut: np.ndarray) -> np.ndarray | None:
    """:math:`F_i = w_i m g l_i / d` (..., N) in N on taut cables, 0 on slack ones."""
    if mass is None:
        return None
    lengths = np.linalg.norm(sheet.vertices - contact[..., None, :], axis=-1)
    depth = z - obj[..., 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(taut, weights * mass * GRAVITY * lengths / depth[..., None], 0.0)


def _recover(team: SheetTeam, R: np.ndarray, t: int, chunk: int
             ) -> tuple[State | None, int]:
    """First step >= t (within ``chunk`` steps) with a stable state: (its lowest state,
    step), or (None, end of the chunk)."""
    end = min(len(R), t + chunk)
    found = np.flatnonzero(fk_stable_batch(team, R[t:end]))
    if not len(found):
        return None, end
    t += int(found[0])
    lowest = fk_result(team, R[t]).lowest
    assert lowest is not None
    return from_equilibrium(lowest, team.sheet, R[t], team.hold_height), t


def _follow(tracker: Tracker, R: np.ndarray, state: State, t: int, chunk: int,
            rec: _Record) -> tuple[State, int, bool]:
    """Track ``state``'s support over steps t..t+chunk in one solve (compiled, or one
    batched numpy solve); returns the last valid state, the first step not stored, and
    whether the chunk ended valid."""
    end = min(len(R), t + chunk)
    k, (valid, ro, vo, zo, w, tight) = tracker.follow(state, R[t:end])
    if k:
        rec.store_branch(t, k, ro[:k], vo[:k], zo[:k], w[:k], tight[:k])
        state = State(state.support, members(tight[k - 1]), ro[k - 1], vo[k - 1],
                      float(zo[k - 1]), w[k - 1])
    return state, t + k, k == end - t


def _run(tracker: Tracker, R: np.ndarray, state: State, rec: _Record,
         events: list[SimulationEvent], crossings: dict[int, tuple[float, np.ndarray]]
         ) -> None:
    """The driver loop: chunked branch following, events resolved step by step."""
    T = len(R)
    motion = np.abs(np.diff(R, axis=0)).max(axis=(1, 2)) if T > 1 else np.zeros(0)
    t, chunk = 1, 64
    cur: State | None = state
    while t < T:
        if cur is None:                                    # lost: look for a rest state
            cur, t_found = _recover(tracker.team, R, t, chunk)
            if cur is None:
                t, chunk = t_found, min(4 * chunk, 4096)
                continue
            events.append(make_event(t_found, 0.0, "recovered", None, cur))
            rec.store(t_found, cur)
            t, chunk = t_found + 1, 64
            continue
        if tracker.trackable(cur):
            cur, t, whole = _follow(tracker, R, cur, t, chunk, rec)
            if whole:
                chunk = min(4 * chunk, 4096)
                continue
            chunk = 64
        cur = resolve_step(tracker, cur, R[t - 1], R[t], t, float(motion[t - 1]), events,
                           crossings)
        rec.store(t, cur)
        t += 1


def _outcome(events: list[SimulationEvent] | tuple[SimulationEvent, ...], lost_now: bool
             ) -> tuple[bool, str, str]:
    """success, status, message of a run (or a step) from its events."""
    lost = [e for e in events if e.kind == "lost"]
    jumps = sum(e.kind == "jump" for e in events)
    if not lost and not lost_now:
        return True, "ok", f"object rested stably throughout ({len(events)} event(s), " \
                           f"{jumps} jump(s))"
    where = f"at step {lost[0].step}" if lost else "before this step"
    back = any(e.kind == "recovered" for e in events) and not lost_now
    return False, "diverged", (f"object lost {where} (it reached the ground: no stable "
                               f"rest state){'; recovered later' if back else ''}")


def simulate(team: SheetTeam, formations: ArrayLike, *, start: ArrayLike | None = None,
             backend: Backend = "auto") -> SimulationResult:
    """Quasi-static simulation of the object along a time series of formations.

    Parameters
    ----------
    team : SheetTeam
        The sheet, the holding height :math:`z_r` and, optionally, the object mass (kg)
        for the tensions :math:`F_i = w_i m g l_i / d` (N).
    formations : array_like, shape (T, N, 2)
        Robot positions at each step (world frame, sheet units). Steps should be small
        enough that no branch appears and vanishes between two samples.
    start : array_like, shape (3,), optional
        Reference object position: the simulation starts at the stable equilibrium of
        ``formations[0]`` nearest to it (default: the lowest).
    backend : {"auto", "numba", "numpy"}
        Branch following by the compiled support solve (``"auto"``: when numba is
        installed) or by the numpy path; both give the same states.

    Returns
    -------
    SimulationResult
        ``success`` false (status ``diverged``) when the object was lost at some step.

    Raises
    ------
    InvalidInputError
        Bad shapes or values.
    InfeasibleFormationError
        Some formation would tear the sheet; ``.step`` is its index.
    InvalidTrajectoryError
        No stable rest state at step 0.

    Examples
    --------
    >>> import numpy as np
    >>> from taut.sheet import Sheet, SheetTeam, simulate
    >>> square = Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]])
    >>> R0 = 0.8 * square.vertices
    >>> path = R0 + np.linspace(0, 0.5, 11)[:, None, None] * [1.0, 0.0]   # slide along x
    >>> res = simulate(SheetTeam(square, 1.5), path)
    >>> res.success, res.status, len(res), res.events
    (True, 'ok', 11, ())
    >>> bool(np.allclose(res.object[-1] - res.object[0], [0.5, 0, 0]))
    True
    """
    team = require_team(team)
    sheet, z, mass = team.sheet, team.hold_height, team.mass
    compiled = _compiled(backend)
    R = check_formations(sheet, as_array(formations, "formations", ndim=3))
    T, N = R.shape[:2]
    if T == 0:
        raise InvalidInputError("formations", "needs at least one step")
    state = _initial_state(team, R[0], start, "formations")
    rec = _Record(T, N)
    rec.store(0, state)
    events: list[SimulationEvent] = []
    crossings: dict[int, tuple[float, np.ndarray]] = {}
    _run(Tracker(team, compiled=compiled), R, state, rec, events, crossings)
    tensions = _tensions(sheet, z, mass, rec.con, rec.obj, rec.wts, rec.taut)
    taut_sets = tuple(tuple(int(i) for i in np.flatnonzero(row)) for row in rec.taut)
    events += _taut_changes(taut_sets, rec.obj, events, crossings)
    events.sort(key=lambda e: (e.step, e.fraction))
    ok, status, message = _outcome(events, bool(np.isnan(rec.obj[-1, 0])))
    return SimulationResult(rec.obj, rec.con, taut_sets, rec.wts, tensions, tuple(events), R,
                            z, mass, ok, status, message)


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
