"""The stateful quasi-static simulator for control loops (the peers' stepping simulators):
move the robots by formation or by velocities, step, read the object. It follows the
object's branch with the tracker of :func:`taut.sheet.sim.simulate` (:mod:`._branch`; model in
docs/sheet_kinematics.md §1-§5, FK paper Sec. II)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_array, as_positive
from ...errors import InvalidInputError, InvalidTrajectoryError
from . import _branch
from ._branch import State, Tracker, fk_result, from_equilibrium, make_event, resolve_step
from .results import SimulationEvent, SimulatorState
from ..model import GEOMETRY_RTOL, check_formation
from .._options import Backend
from .simulate import _compiled, _initial_state, _tensions
from ..team import SheetTeam, require_team

__all__ = ["Simulator"]


class Simulator:
    """Stateful quasi-static simulator for control loops: move the robots (by formation or
    by velocities over ``dt``), step, read the object (:attr:`state`).

    It shares the branch tracker of :func:`simulate` (:mod:`._branch`): each step follows
    the object's branch from the previous formation to the new one (straight-line
    interpolation), through taut-set changes and jumps, exactly as :func:`simulate` does
    between two samples.

    Parameters
    ----------
    team : SheetTeam
        The sheet, the holding height :math:`z_r` and, optionally, the object mass (kg)
        for the tensions (N).
    formation : array_like, shape (N, 2)
        Initial robot positions (sheet units).
    start : array_like, shape (3,), optional
        Reference object position: the simulator starts at the stable state of
        ``formation`` closest to it (default: the lowest).
    dt : float
        Default time step (s) of :meth:`step` with velocities (1/30, as the peers').
    backend : {"auto", "numba", "numpy"}
        As in :func:`simulate`: the compiled branch follower (one compiled call per step
        without events) or the numpy path; both give the same states.

    Attributes
    ----------
    team : SheetTeam
        The team simulated.
    dt : float
        The default time step, s.
    initial : SimulatorState
        The state before the first step.

    Raises
    ------
    InvalidInputError
        Bad shapes or values; InvalidTrajectoryError when ``formation`` has no stable
        rest state.
    InfeasibleFormationError
        ``formation`` (or a later one) would tear the sheet.

    Examples
    --------
    >>> import numpy as np
    >>> from taut.sheet import Sheet, SheetTeam, Simulator
    >>> square = Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]])
    >>> sim = Simulator(SheetTeam(square, 1.5), 0.8 * square.vertices)
    >>> v = np.tile([0.3, 0.0], (4, 1))                  # every robot at 0.3 units/s in x
    >>> for _ in range(10):
    ...     state = sim.step(velocities=v, dt=0.1)
    >>> state.status, state.step, round(state.time, 6)
    ('ok', 10, 1.0)
    >>> bool(np.allclose(state.object[:2], sim.initial.object[:2] + [0.3, 0.0]))
    True
    """

    def __init__(self, team: SheetTeam, formation: ArrayLike, *,
                 start: ArrayLike | None = None, dt: float = 1.0 / 30.0,
                 backend: Backend = "auto") -> None:
        self.team = team = require_team(team)
        sheet = team.sheet
        self.dt = as_positive(dt, "dt")
        R = check_formation(sheet, as_array(formation, "formation", shape=(sheet.n, 2)))
        self._tracker = Tracker(team, single_fast=True, compiled=_compiled(backend))
        limit = sheet.side_lengths() * (1 + GEOMETRY_RTOL) + GEOMETRY_RTOL * sheet.size
        self._limit2 = np.ascontiguousarray(limit * limit)          # (N, N)
        self._iu, self._ju = np.triu_indices(sheet.n, 1)
        self._cur: State | None = _initial_state(team, R, start, "formation")
        self._R = R.copy()
        self._velocities = np.zeros_like(R)
        self._steps, self._time = 0, 0.0
        self._messages: dict[tuple[int, ...], str] = {}
        self._state = self._snapshot(())
        self.initial = self._state

    @property
    def state(self) -> SimulatorState:
        """The object after the last step."""
        return self._state

    @property
    def velocities(self) -> np.ndarray:
        """The robot velocities (N, 2) used by :meth:`step` when none are given."""
        return self._velocities.copy()

    def _snapshot(self, events: tuple[SimulationEvent, ...]) -> SimulatorState:
        s, N = self._cur, self.team.n
        if s is None:
            return SimulatorState(self._steps, self._time, self._R.copy(), np.full(3, np.nan),
                                  np.full(2, np.nan), (), np.zeros(N), None, events, False,
                                  "diverged", "object lost (no stable rest state)")
        obj = np.empty(3)
        obj[:2] = s.ro
        obj[2] = s.z
        ten = None
        team = self.team
        if team.mass is not None:
            taut = np.zeros(N, dtype=bool)
            taut[list(s.taut)] = True
            ten = _tensions(team.sheet, team.hold_height, team.mass, s.vo, obj, s.w, taut)
        message = self._messages.get(s.taut)
        if message is None:
            if len(self._messages) > 1024:
                self._messages.clear()
            message = self._messages[s.taut] = (f"object resting on cables "
                                                f"{[i + 1 for i in s.taut]}")
        return SimulatorState._resting(self._steps, self._time, self._R.copy(), obj,
                                       s.vo.copy(), s.taut, s.w.copy(), ten, events, message)

    def _next_formation(self, formation: object | None, velocities: object | None,
                        dt: float | None) -> tuple[np.ndarray, float, float]:
        """The next formation, the step's duration and its largest coordinate motion."""
        if formation is not None and velocities is not None:
            raise InvalidInputError("formation", "give a formation or velocities, not both")
        step_dt = self.dt if dt is None else as_positive(dt, "dt")
        N = self.team.n
        if formation is None and self._tracker.compiled:
            # The control-loop path: velocities checked and applied in one compiled call
            # (a non-finite or tearing result takes the validating path below).
            v = velocities
            if v is not None and not (type(v) is np.ndarray and v.dtype == np.float64
                                      and v.shape == (N, 2)):
                v = as_array(v, "velocities", shape=(N, 2))
            vel = self._velocities if v is None else v
            R1 = np.empty((N, 2))
            ok, motion = _branch._stk.feasible_step(self._R, vel, step_dt, self._limit2, R1)
            if ok:
                if v is not None:
                    self._velocities = vel.copy()
                return R1, step_dt, motion
        if formation is not None:
            R1 = as_array(formation, "formation", shape=(N, 2))
        else:
            if velocities is not None:
                self._velocities = as_array(velocities, "velocities", shape=(N, 2))
            R1 = self._R + self._velocities * step_dt
        gap = R1[self._iu] - R1[self._ju]
        if np.any(np.einsum("pk,pk->p", gap, gap) > self._limit2[self._iu, self._ju]):
            check_formation(self.team.sheet, R1)   # raises with the pair named (and the step)
        return R1, step_dt, float(np.abs(R1 - self._R).max())

    def step(self, formation: ArrayLike | None = None, *, velocities: ArrayLike | None = None,
             dt: float | None = None) -> SimulatorState:
        """Advance one step and return the new :attr:`state`.

        Parameters
        ----------
        formation : array_like, shape (N, 2), optional
            The robots' new positions. Otherwise they move by ``velocities * dt``.
        velocities : array_like, shape (N, 2), optional
            Robot velocities (sheet units per second); kept for later steps. Default: the
            last ones given (initially zero).
        dt : float, optional
            Step duration (s); default the simulator's ``dt``.

        Returns
        -------
        SimulatorState
            ``events`` holds what happened during this step.

        Raises
        ------
        InvalidInputError, InfeasibleFormationError
            Bad input, or a formation that would tear the sheet (the state is unchanged).
        """
        R1, step_dt, motion = self._next_formation(formation, velocities, dt)
        self._steps += 1
        self._time += step_dt
        events: list[SimulationEvent] = []
        before = self._cur
        if before is None:
            lowest = fk_result(self.team, R1).lowest
            if lowest is not None:
                self._cur = from_equilibrium(lowest, self.team.sheet, R1,
                                             self.team.hold_height)
                events.append(make_event(self._steps, 0.0, "recovered", None, self._cur))
        else:
            crossings: dict[int, tuple[float, np.ndarray]] = {}
            self._cur = resolve_step(self._tracker, before, self._R, R1, self._steps, motion,
                                     events, crossings)
            if self._cur is not None and self._cur.taut != before.taut and not events:
                frac, where = crossings.get(self._steps,
                                            (1.0, np.array([*self._cur.ro, self._cur.z])))
                events.append(SimulationEvent(self._steps, frac, "taut_change", before.taut,
                                              self._cur.taut, where.copy(), where.copy(), 0.0))
        self._R = R1
        self._state = self._snapshot(tuple(events))
        return self._state
