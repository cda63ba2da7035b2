"""Time-stamped samples of an SE(2) plan: rigid motions of a formation between waypoints,
and in-place formation changes.

A rigid piece moves the object's projection and the heading linearly between waypoints,
both at once: the piece takes ``max(|dp| / speed, |dpsi| / rotation_speed)`` seconds.
Samples are spaced so no robot moves more than ``SAMPLE_STEP`` between two. The planned
object rides rigidly with the formation (it is the formation's origin at its height).

A formation change moves every robot straight from the old formation to the new one (same
object projection and heading) at the team's speed, sampled every ``REFORM_STEP`` of robot
motion; the object's planned states there come from the quasi-static simulation
(:func:`taut.sheet.sim.simulate`) followed from the state before the change.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ...errors import TautError
from ...sheet import simulate
from .. import _tol
from ..checks._geometry import pair_closest
from ..formations.optimal import Formation
from ..world import Scenario

__all__ = ["Piece", "SampledMotion", "sample_pieces", "ChangeProfile", "change_profile"]


@dataclass(frozen=True, eq=False)
class Piece:
    """A rigid piece (``waypoints`` (K, 3) of ``formation``) or, with ``to`` set, a change
    from ``formation`` into ``to`` at state ``waypoints[0]``."""

    formation: Formation
    waypoints: np.ndarray
    to: Formation | None = None


@dataclass(frozen=True, eq=False)
class SampledMotion:
    """Samples of a plan: ``times`` (T,), ``centre`` (T, 2), ``heading`` (T,), ``robots``
    (T, N, 2), planned ``object`` (T, 3); ``message`` is set when a formation change has no
    continuous rest state (the plan is then unusable)."""

    times: np.ndarray
    centre: np.ndarray
    heading: np.ndarray
    robots: np.ndarray
    object: np.ndarray
    message: str | None = None

    @property
    def duration(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0

    @property
    def path_length(self) -> float:
        """Planar length of the object's path, m."""
        return float(np.linalg.norm(np.diff(self.object[:, :2], axis=0), axis=1).sum())


class _Samples:
    def __init__(self, formation: Formation, state: np.ndarray) -> None:
        self.t = [0.0]
        self.c = [state[:2].copy()]
        self.h = [float(state[2])]
        self.r = [formation.placed(state[:2], np.asarray(state[2]))]
        self.o = [np.array([*state[:2], formation.object_height])]

    def rigid(self, f: Formation, a: np.ndarray, b: np.ndarray, speed: float, omega: float
              ) -> None:
        radius = float(np.linalg.norm(f.robots, axis=1).max())
        dp, dpsi = float(np.hypot(*(b[:2] - a[:2]))), abs(float(b[2] - a[2]))
        if dp + dpsi <= _tol.ANGLE_TOL:
            return
        k = max(1, int(np.ceil((dp + radius * dpsi) / _tol.SAMPLE_STEP)))
        s = np.arange(1, k + 1) / k
        dur = max(dp / speed, dpsi / omega)
        st = a[None] + s[:, None] * (b - a)[None]
        self.t.extend(self.t[-1] + s * dur)
        self.c.extend(st[:, :2])
        self.h.extend(st[:, 2])
        self.r.extend(f.placed(st[:, :2], st[:, 2]))
        self.o.extend(np.column_stack([st[:, :2], np.full(k, f.object_height)]))

    def reform(self, scenario: Scenario, f: Formation, g: Formation) -> str | None:
        team = scenario.team
        c, h = self.c[-1], self.h[-1]
        a, b = self.r[-1], g.placed(c, np.asarray(h))
        change = _simulate_change(scenario, a, b, self.o[-1], np.array([*c, g.object_height]))
        if isinstance(change, str):
            return change
        robots, obj, dist = change
        k = len(robots) - 1
        if k <= 0:
            return None
        self.t.extend(self.t[-1] + np.arange(1, k + 1) / k * dist / team.speed)
        self.c.extend([c] * k)
        self.h.extend([h] * k)
        self.r.extend(robots[1:])
        self.o.extend(obj[1:])
        return None


def _closest_pass(a: np.ndarray, b: np.ndarray) -> tuple[float, int, int]:
    """Least distance between two robots moving straight from ``a`` to ``b`` (N, 2) at
    the same time, m, and which pair: each pair's relative position is linear in time."""
    iu, ju = np.triu_indices(len(a), 1)
    gap = pair_closest(a, b)
    k = int(np.argmin(gap))
    return float(gap[k]), int(iu[k]), int(ju[k])


def _simulate_change(scenario: Scenario, a: np.ndarray, b: np.ndarray, start: np.ndarray,
                     end: np.ndarray) -> str | tuple[np.ndarray, np.ndarray, float]:
    """Robots moving straight from ``a`` to ``b`` (N, 2), sampled every ``REFORM_STEP``,
    and the object followed from ``start`` by the quasi-static simulation; it must end at
    ``end``. Returns (robots (K+1, N, 2), object (K+1, 3), largest robot displacement)
    or why the change is not usable."""
    team = scenario.team
    dist = float(np.linalg.norm(b - a, axis=1).max())
    if dist <= 0.0:
        return a[None], np.asarray(start, float)[None], 0.0
    gap, i, j = _closest_pass(a, b)
    if gap < 2 * team.robot_radius:
        return (f"robots {i + 1} and {j + 1} would pass {gap:.3g} m apart during a formation "
                f"change (footprints overlap)")
    k = max(2, int(np.ceil(dist / _tol.REFORM_STEP)))
    s = np.arange(0, k + 1) / k
    robots = a[None] + s[:, None, None] * (b - a)[None]
    try:
        sim = simulate(team.carrier, robots, start=start)
    except TautError as exc:
        return f"formation change has no rest state ({exc.problem})"
    bad = [e for e in sim.events if e.kind in ("jump", "lost")]
    if bad:
        return ("the object jumps during a formation change (drop "
                f"{bad[0].drop:.3g} m)" if bad[0].kind == "jump" else
                "the object is lost (reaches the ground) during a formation change")
    if np.linalg.norm(sim.object[-1] - end) > _tol.OBJECT_RTOL * team.sheet.size:
        return "a formation change does not end in the new formation's rest state"
    obj = sim.object.copy()
    obj[-1] = end
    return robots, obj, dist


@dataclass(frozen=True, eq=False)
class ChangeProfile:
    """The quasi-static simulation of an in-place change between two formations (the
    model is invariant under planar rigid motions, so it is the same wherever the change
    happens): ``message`` None when usable; ``lowest`` the lowest object height on the
    way, m; ``duration`` s."""

    message: str | None
    lowest: float
    duration: float


@functools.lru_cache(maxsize=256)
def change_profile(scenario: Scenario, f: Formation, g: Formation) -> ChangeProfile:
    """:class:`ChangeProfile` of the change from ``f`` to ``g`` (memoised)."""
    zero = np.zeros(2)
    change = _simulate_change(scenario, f.placed(zero, np.asarray(0.0)),
                              g.placed(zero, np.asarray(0.0)),
                              np.array([0.0, 0.0, f.object_height]),
                              np.array([0.0, 0.0, g.object_height]))
    if isinstance(change, str):
        return ChangeProfile(change, -np.inf, np.inf)
    _, obj, dist = change
    lowest = float(obj[:, 2].min())
    safety = scenario.team.height_safety
    if lowest < safety - _tol.GEOMETRY_TOL:
        return ChangeProfile(f"the object comes down to {lowest:.3g} m during the change, "
                             f"below the height safety {safety:.3g} m", lowest, np.inf)
    return ChangeProfile(None, lowest, dist / scenario.team.speed)


def sample_pieces(scenario: Scenario, pieces: list[Piece]) -> SampledMotion:
    """Sample a plan made of rigid pieces and formation changes (module docstring)."""
    team = scenario.team
    first = pieces[0]
    smp = _Samples(first.formation, first.waypoints[0])
    message = None
    for p in pieces:
        if p.to is not None:
            message = message or smp.reform(scenario, p.formation, p.to)
            continue
        w = p.waypoints
        # Same heading as the last sample, up to whole turns (headings are unwrapped).
        w = w.copy()
        w[:, 2] += 2 * np.pi * np.round((smp.h[-1] - w[0, 2]) / (2 * np.pi))
        for a, b in zip(w[:-1], w[1:]):
            smp.rigid(p.formation, a, b, team.speed, team.rotation_speed)
    return SampledMotion(np.asarray(smp.t), np.asarray(smp.c), np.asarray(smp.h),
                         np.asarray(smp.r), np.asarray(smp.o), message)
