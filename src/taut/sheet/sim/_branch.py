"""The branch tracker of quasi-static simulation, shared by :func:`simulate` and
:class:`Simulator` (docs/sheet_kinematics.md §1-§5; FK paper Sec. II).

A branch is followed by re-solving its *support* (3..5 taut cables with affinely
independent lifted points) on each new formation with the same tests as forward
kinematics. When the support stops being valid between two formations, the crossing is
located by grid refinement and the object either continues on a neighbouring taut set, on a
nearby stable FK state, or rolls (steepest descent, :mod:`._descent`) to another minimum.

Hooks for a prepared FK solver: every per-step solve goes through :func:`solve_taut_sets`
(the kernel's fixed-set Lagrange solve) and every full forward-kinematics call through
:func:`fk_stable` .
"""

from __future__ import annotations

from types import ModuleType
from typing import Literal
import numpy as np

from ._descent import descend
from .._lifted import Frame
from .._tol import (ARRIVAL_ACTIVE_TOL, ARRIVAL_RTOL, CONTINUATION_RTOL, DEGENERATE_STEP,
    EVENT_STEP_TOL, SUBSETS_UP_TO)
from ..._jit import HAVE_NUMBA
from ..fk.solver import cached_solver
from .results import EventKind, SimulationEvent
from ..fk.results import Equilibrium, FKResult
from ._support import (SetSolution, State, branch, from_equilibrium, members, nearest,
    neighbour_sets, solve_support_one, solve_taut_sets)
from ..team import SheetTeam

__all__ = ["State", "Tracker", "solve_taut_sets", "branch", "fk_result", "fk_stable",
           "fk_stable_batch", "from_equilibrium", "nearest", "resolve_step", "make_event",
           "members"]

_J = np.array([1.0, 1.0, -1.0, -1.0])
_stk: ModuleType = None  # type: ignore[assignment]   # taut.sheet._kernels.step, once loaded


def _load_step_kernel() -> None:
    """Import the compiled branch follower (and numba) on the first tracker using it."""
    global _stk
    if _stk is None:
        from .._kernels import step as _step_kernel
        _stk = _step_kernel


FKMethod = Literal["fast", "exhaustive", "subsets"]


class Tracker:
    """Follows the object's branch for one sheet team (module docstring).

    ``single_fast`` switches the one-formation re-solve of :meth:`valid_at` to
    :func:`solve_support_one` (same tests, no batching overhead; used by the stepping
    :class:`Simulator`)."""

    def __init__(self, team: SheetTeam, *, single_fast: bool = False,
                 compiled: bool | None = None):
        self.team = team
        sheet, z = team.sheet, team.hold_height
        self.sheet, self.z = sheet, z
        self.N = sheet.n
        self.single_fast = single_fast
        self._v_centre = sheet.vertices.mean(axis=0)
        self._Xv = np.ascontiguousarray((sheet.vertices - self._v_centre) / sheet.size)
        #: Branch following by the compiled support solve of ``_step_kernel`` (numba);
        #: False: the numpy path (``solve_support_one`` / :func:`branch`), same answers.
        self.compiled = HAVE_NUMBA if compiled is None else bool(compiled and HAVE_NUMBA)
        self._args = (self._Xv, float(self._v_centre[0]), float(self._v_centre[1]),
                      float(sheet.size), float(z))
        self._width = 5 + 2 * self.N                      # _step_kernel.step_width(N)
        self._supports: dict[tuple[int, ...], np.ndarray] = {}
        self._taut_sets: dict[bytes, tuple[int, ...]] = {}
        if self.compiled:
            _load_step_kernel()

    def _support_array(self, support: tuple[int, ...]) -> np.ndarray:
        arr = self._supports.get(support)
        if arr is None:
            if len(self._supports) > 256:
                self._supports.clear()
            arr = self._supports[support] = np.array(support, dtype=np.int64)
        return arr

    def _row_state(self, support: tuple[int, ...], row: np.ndarray) -> State:
        """The tracker's state from one output row of ``_step_kernel.solve_support``."""
        N = self.N
        mask = row[5 + N:].tobytes()
        taut = self._taut_sets.get(mask)
        if taut is None:
            if len(self._taut_sets) > 1024:
                self._taut_sets.clear()
            taut = self._taut_sets[mask] = tuple(np.flatnonzero(row[5 + N:]).tolist())
        return State(support, taut, row[0:2], row[2:4], float(row[4]), row[5:5 + N])

    def follow(self, state: State, R: np.ndarray) -> tuple[int, SetSolution]:
        """Re-solve ``state``'s support on formations ``R`` (T, N, 2) in order up to the
        first one where it fails: one compiled call (``_step_kernel.follow_support``) or
        one batched numpy solve (:func:`branch`). Returns that count ``k`` and the
        ``SetSolution`` arrays (their first ``k`` rows are the valid states)."""
        if not self.compiled:
            sol = branch(self.sheet, R, self.z, state.support)
            bad = np.flatnonzero(~sol[0])
            return (int(bad[0]) if len(bad) else len(R)), sol
        T, N = len(R), self.N
        out = np.empty((T, self._width))
        support = self._support_array(state.support)
        k = _stk.follow_support(np.ascontiguousarray(R), *self._args, support, len(support),
                                out)
        valid = np.zeros(T, dtype=bool)
        valid[:k] = True
        return k, (valid, out[:, 0:2], out[:, 2:4], out[:, 4], out[:, 5:5 + N],
                   out[:, 5 + N:] > 0.5)

    def trackable(self, state: State) -> bool:
        return 3 <= len(state.support) <= 5

    def valid_at(self, state: State, R: np.ndarray) -> tuple[bool, State | None]:
        if not self.trackable(state):
            return False, None
        if self.compiled:
            out = np.empty(self._width)
            support = self._support_array(state.support)
            Xv, vcx, vcy, size, z = self._args
            if not _stk.solve_support(R, Xv, vcx, vcy, size, z, support, len(support), out):
                return False, None
            return True, self._row_state(state.support, out)
        if self.single_fast:
            one = solve_support_one(self._Xv, self._v_centre, self.sheet.size, self.z, R,
                                    state.support)
            if one is None:
                return False, None
            ro1, vo1, zo1, w1, tight1 = one
            return True, State(state.support, members(tight1), ro1, vo1, zo1, w1)
        valid, ro, vo, zo, w, tight = branch(self.sheet, R[None], self.z, state.support)
        if not valid[0]:
            return False, None
        return True, State(state.support, members(tight[0]), ro[0], vo[0], float(zo[0]),
                            w[0])

    def crossing(self, state: State, R0: np.ndarray, R1: np.ndarray, s0: float
                 ) -> tuple[float, float, State]:
        """Last valid fraction s_lo (with its state) and first invalid s_hi > s_lo."""
        lo, hi, at_lo = s0, 1.0, state
        while hi - lo > EVENT_STEP_TOL:
            s = np.linspace(lo, hi, 18)[1:-1]
            R = (1 - s)[:, None, None] * R0 + s[:, None, None] * R1
            k, (valid, ro, vo, zo, w, tight) = self.follow(state, R)
            if k > 0:
                lo = float(s[k - 1])
                at_lo = State(state.support, members(tight[k - 1]), ro[k - 1], vo[k - 1],
                               float(zo[k - 1]), w[k - 1])
            if k < len(s):
                hi = float(s[k])
        return lo, hi, at_lo

    def stable_states(self, R: np.ndarray) -> tuple[Equilibrium, ...]:
        """Stable FK states of one formation. Events happen at degenerate places (just
        past a taut-set change, or leaving an all-taut IK formation) where the hull-based
        method can miss states, so small teams use the complete 'subsets' method and
        larger ones fall back to it when 'fast' finds none."""
        method: FKMethod = "subsets" if self.N <= SUBSETS_UP_TO else "fast"
        stable = fk_stable(self.team, R, method)
        if not stable and method == "fast":
            stable = fk_stable(self.team, R, "subsets")
        return stable

    def _neighbour_continuation(self, R: np.ndarray, before: State, cont_tol: float
                                ) -> State | None:
        """The state on a taut set one cable away from ``before``'s support within
        ``cont_tol`` of it (no FK call, exact at transitions where forward kinematics'
        tolerance-based taut sets are ambiguous)."""
        if not self.trackable(before):
            return None
        idx = neighbour_sets(before.support, self.N)
        if not len(idx):
            return None
        valid, ro, vo, zo, w, tight = solve_taut_sets(self.sheet, R[None], self.z,
                                                      np.zeros(len(idx), np.intp), idx)
        pts = np.column_stack([ro, vo, zo])
        dist = np.where(valid, np.linalg.norm(pts - before.point, axis=1), np.inf)
        k = int(np.argmin(dist))
        if dist[k] > cont_tol:
            return None
        return State(members(idx[k][idx[k] >= 0]), members(tight[k]), ro[k], vo[k],
                     float(zo[k]), w[k])

    def settle(self, R: np.ndarray, before: State, cont_tol: float
               ) -> tuple[State | None, EventKind | None]:
        """State at formation ``R`` reached from ``before`` (continuation or descent).

        A continuation is tried first among the taut sets one cable away from the
        current one, then among FK's stable states; failing both, the object rolls
        (:meth:`roll`)."""
        new = self._neighbour_continuation(R, before, cont_tol)
        stable: tuple[Equilibrium, ...] = ()
        if new is None:
            stable = self.stable_states(R)
            if stable:
                j, dist = nearest(stable, before.point)
                if dist <= cont_tol:
                    new = from_equilibrium(stable[j], self.sheet, R, self.z)
        if new is not None:
            return new, ("taut_change" if new.taut != before.taut else None)
        return self.roll(R, before, stable)

    def roll(self, R: np.ndarray, before: State, stable: tuple[Equilibrium, ...]
             ) -> tuple[State | None, EventKind]:
        """The branch ended: steepest descent from ``before``, then the descent's end
        point's active set (or the nearest of the ``stable`` FK states)."""
        size = self.sheet.size
        frame = Frame.build(self.sheet.vertices, R[None], self.z, size)
        P = frame.P[0]

        def to_world(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return x[:2] * size + frame.r_centre[0], x[2:] * size + frame.v_centre

        def arrive(active: np.ndarray, x: np.ndarray) -> State | None:
            if not 3 <= len(active) <= 5:
                return None
            idx = np.full((1, 5), -1, dtype=np.intp)
            idx[0, :len(active)] = active
            valid, ro, vo, zo, w, tight = solve_taut_sets(self.sheet, R[None], self.z,
                                                          np.zeros(1, np.intp), idx)
            ro_x, vo_x = to_world(x)
            near = np.linalg.norm(np.r_[ro[0] - ro_x, vo[0] - vo_x]) <= ARRIVAL_RTOL * size
            if not (valid[0] and near):
                return None
            return State(members(active), members(tight[0]), ro[0], vo[0], float(zo[0]),
                         w[0])

        x0 = np.concatenate([(before.ro - frame.r_centre[0]) / size,
                             (before.vo - frame.v_centre) / size])
        out = descend(P, x0, arrive, -frame.z ** 2, active_tol=ARRIVAL_ACTIVE_TOL)
        if isinstance(out, State):
            return out, "jump"
        if out is None:
            return None, "lost"
        vals = out @ (_J * out) + P[:, :4] @ out + P[:, 4]
        ro, vo = to_world(out)
        zo = self.z - np.sqrt(max(-float(vals.max()), 0.0)) * size
        if not stable:
            return None, "lost"
        j, _ = nearest(stable, np.concatenate([ro, vo, [zo]]))
        if stable[j].height > before.z + CONTINUATION_RTOL * size:
            # A roll only lowers the object: a nearest state above the start is not where
            # it ends (the descent stopped short; seen as a -7 cm "drop" where the other
            # backend's descent, from 1e-9 away, reached the floor: issue 25).
            return None, "lost"
        return from_equilibrium(stable[j], self.sheet, R, self.z), "jump"


def make_event(step: int, frac: float, kind: EventKind, a: State | None, b: State | None
               ) -> SimulationEvent:
    """The event ``kind`` at ``step`` (fraction ``frac``) from state ``a`` to ``b``."""
    nan3 = np.full(3, np.nan)
    pa = nan3 if a is None else np.array([*a.ro, a.z])
    pb = nan3 if b is None else np.array([*b.ro, b.z])
    return SimulationEvent(step, frac, kind, () if a is None else a.taut,
                           () if b is None else b.taut, pa, pb, float(pa[2] - pb[2]))


def resolve_step(tracker: Tracker, state: State, R0: np.ndarray, R1: np.ndarray,
                 step: int, motion: float, events: list[SimulationEvent],
                 crossings: dict[int, tuple[float, np.ndarray]]) -> State | None:
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
            lo, hi, before = s0, min(1.0, s0 + DEGENERATE_STEP), state
        Rh = (1 - hi) * R0 + hi * R1
        if tracker.trackable(before) and branch(tracker.sheet, Rh[None], tracker.z,
                                                 before.support)[3][0] <= 0.0:
            events.append(make_event(step, hi, "lost", before, None))     # on the ground
            return None
        cont_tol = CONTINUATION_RTOL * size + 100.0 * (hi - lo) * motion
        new, kind = tracker.settle(Rh, before, cont_tol)
        if kind is not None:
            if kind == "taut_change":
                crossings.setdefault(step, (hi, np.array([*before.ro, before.z])))
            else:
                events.append(make_event(step, hi, kind, before, new))
        if new is None:
            return None
        state, s0 = new, hi
        if s0 >= 1.0:
            return state
    stable = fk_stable(tracker.team, R1, "fast")  # pragma: no cover - safeguard
    if not stable:                                            # pragma: no cover
        events.append(make_event(step, 1.0, "lost", state, None))
        return None
    j, _ = nearest(stable, state.point)                       # pragma: no cover
    return from_equilibrium(stable[j], tracker.sheet, R1, tracker.z)  # pragma: no cover


# ------------------------------------------------------------------ forward-kinematics hooks
# The only places simulation calls full forward kinematics: the team's cached FK solver
# (the engine behind :func:`forward_kinematics`; the team is validated already).

def fk_result(team: SheetTeam, R: np.ndarray, method: FKMethod = "fast") -> FKResult:
    """Forward kinematics of one formation R (N, 2)."""
    return cached_solver(team, method).solve(R)


def fk_stable(team: SheetTeam, R: np.ndarray, method: FKMethod = "fast"
              ) -> tuple[Equilibrium, ...]:
    """Stable equilibria of one formation R (N, 2)."""
    return fk_result(team, R, method).stable


def fk_stable_batch(team: SheetTeam, R: np.ndarray) -> np.ndarray:
    """Bool (B,): formation ``R[b]`` (B, N, 2) has a stable equilibrium. Reads the lazy
    batch's ``success``, which runs the direct minimisation only next to a similar copy
    of the sheet; ``stable`` would run it on every formation without a stable state
    (bench/bench_sim_recover.py: 2-20x the batch's cost on a lost object)."""
    return np.asarray(cached_solver(team, "fast").solve_batch(R).success)
