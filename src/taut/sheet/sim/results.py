"""Result types of quasi-static simulation: events, the whole-trajectory result of
:func:`taut.sheet.sim.simulate` and the per-step state of :class:`taut.sheet.Simulator`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..._outcome import check_status
from ..._repr import CompactRepr

__all__ = ["EventKind", "SimulationEvent", "SimulationResult", "SimulatorState"]

EventKind = Literal["taut_change", "jump", "lost", "recovered"]


@dataclass(frozen=True, eq=False, repr=False)
class SimulationEvent(CompactRepr):
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


@dataclass(frozen=True, eq=False, repr=False)
class SimulationResult(CompactRepr):
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
    success : bool
        The object rested stably at every step (it may have jumped between branches).
    status : {"ok", "diverged"}
        ``diverged``: the object was lost (reached the ground, no stable state) at some
        step; ``message`` says where and whether it was recovered.
    message : str
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
    success: bool = True
    status: str = "ok"
    message: str = ""

    def __post_init__(self) -> None:
        check_status(self.status)

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



@dataclass(frozen=True, eq=False, repr=False)
class SimulatorState(CompactRepr):
    """The object after a :meth:`taut.sheet.Simulator.step`.

    Attributes
    ----------
    step : int
        Steps taken so far (0 before the first).
    time : float
        Simulated time (sum of the steps' ``dt``; seconds when velocities are in units/s).
    formation : ndarray, shape (N, 2)
        Robot positions (sheet units).
    object : ndarray, shape (3,)
        :math:`\\mathbf{p}_o` (NaN while lost).
    contact : ndarray, shape (2,)
        :math:`\\mathbf{v}_o` (NaN while lost).
    taut : tuple of int
        Taut cables (0-based; empty while lost).
    weights : ndarray, shape (N,)
        Load shares (0 on slack cables).
    tensions : ndarray, shape (N,), or None
        Cable tensions in N when a mass was given.
    events : tuple of SimulationEvent
        Events of the last step (``step`` numbers count simulator steps).
    success : bool
        The object rests stably (not lost).
    status : {"ok", "diverged"}
    message : str
    """

    step: int
    time: float
    formation: np.ndarray
    object: np.ndarray
    contact: np.ndarray
    taut: tuple[int, ...]
    weights: np.ndarray
    tensions: np.ndarray | None
    events: tuple[SimulationEvent, ...] = field(default=())
    success: bool = True
    status: str = "ok"
    message: str = ""

    def __post_init__(self) -> None:
        check_status(self.status)

    @classmethod
    def _resting(cls, step: int, time: float, formation: np.ndarray, obj: np.ndarray,
                 contact: np.ndarray, taut: tuple[int, ...], weights: np.ndarray,
                 tensions: np.ndarray | None, events: tuple[SimulationEvent, ...],
                 message: str) -> "SimulatorState":
        """A successful state (status ``ok``) built without the dataclass machinery
        (``Simulator.step``'s per-step cost in control loops)."""
        self = object.__new__(cls)
        self.__dict__.update(step=step, time=time, formation=formation, object=obj,
                             contact=contact, taut=taut, weights=weights, tensions=tensions,
                             events=events, success=True, status="ok", message=message)
        return self
