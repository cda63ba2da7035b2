"""Seeded bidirectional RRT (RRT-Connect, Kuffner & LaValle 2000) in SE(2) with path
shortcutting, on a :class:`~taut.plan.se2._space.PoseChecker`.

States are ``(x, y, psi)``; the distance is the largest robot displacement bound
``|dp| + R |dpsi|`` (``R`` the formation's radius about the object), so one step moves no
robot more than ``step``. Headings are unwrapped towards the tree node they extend, so
every edge turns by at most pi. Both trees may have several roots (every valid heading at
the start, every valid heading at the goal, or a set of formation-change states).

Deterministic: all randomness comes from the ``numpy.random.Generator`` passed in, and
the budget is an iteration count (with a wall-clock cap reported as such).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ._body import BodyChecker
from ._space import PoseChecker

__all__ = ["SearchOutcome", "rrt_connect", "shortcut", "valid_headings"]


@dataclass(frozen=True, eq=False)
class SearchOutcome:
    """Result of :func:`rrt_connect`.

    Attributes
    ----------
    path : ndarray, shape (K, 3) or None
        Waypoints from a start root to a goal root (None when not found).
    iterations : int
    timed_out : bool
        The wall-clock cap stopped the search (otherwise the iteration budget did, or it
        succeeded).
    goal_index : int
        Which goal root the path ends at (-1 when not found).
    """

    path: np.ndarray | None
    iterations: int
    timed_out: bool
    goal_index: int = -1


def valid_headings(checker: PoseChecker, point: np.ndarray, count: int = 72) -> np.ndarray:
    """States ``(K, 3)`` at ``point`` with the ``count`` evenly spaced headings that are
    valid."""
    psi = 2 * np.pi * np.arange(count) / count - np.pi
    states = np.column_stack([np.repeat(np.asarray(point, float)[None], count, axis=0), psi])
    return states[checker.valid(states)]


class _Tree:
    def __init__(self, roots: np.ndarray, capacity: int = 1024) -> None:
        self.nodes = np.zeros((max(capacity, len(roots)), 3))
        self.nodes[:len(roots)] = roots
        self.parent = np.full(len(self.nodes), -1, dtype=int)
        self.root = np.arange(len(self.nodes))
        self.n = len(roots)

    def add(self, state: np.ndarray, parent: int) -> int:
        if self.n == len(self.nodes):
            self.nodes = np.concatenate([self.nodes, np.zeros_like(self.nodes)])
            self.parent = np.concatenate([self.parent, np.full(len(self.parent), -1)])
            self.root = np.concatenate([self.root, np.zeros_like(self.root)])
        self.nodes[self.n] = state
        self.parent[self.n] = parent
        self.root[self.n] = self.root[parent]
        self.n += 1
        return self.n - 1

    def nearest(self, q: np.ndarray, radius: float) -> int:
        d = self.nodes[:self.n] - q
        ang = np.abs(np.angle(np.exp(1j * d[:, 2])))
        return int(np.argmin(np.hypot(d[:, 0], d[:, 1]) + radius * ang))

    def branch(self, i: int) -> np.ndarray:
        out = []
        while i >= 0:
            out.append(self.nodes[i])
            i = int(self.parent[i])
        return np.asarray(out[::-1])


def _towards(a: np.ndarray, q: np.ndarray, step: float, radius: float) -> tuple[np.ndarray, bool]:
    """The state at most ``step`` (robot displacement) from ``a`` towards ``q`` (heading of
    ``q`` unwrapped towards ``a``); True when it is ``q`` itself."""
    q = q.copy()
    q[2] = a[2] + float(np.angle(np.exp(1j * (q[2] - a[2]))))
    d = float(np.hypot(q[0] - a[0], q[1] - a[1]) + radius * abs(q[2] - a[2]))
    if d <= step:
        return q, True
    return a + (q - a) * (step / d), False


def _extend(tree: _Tree, q: np.ndarray, checker: PoseChecker, step: float, greedy: bool
            ) -> tuple[str, int]:
    """Grow ``tree`` towards ``q``: one step, or (``greedy``) until blocked or reached.
    Returns ("reached" | "advanced" | "trapped", index of the last node)."""
    i = tree.nearest(q, checker.radius)
    status = "trapped"
    while True:
        a = tree.nodes[i]
        new, arrived = _towards(a, q, step, checker.radius)
        if not (checker.valid(new[None])[0] and checker.motion_valid(a, new)):
            return status, i
        i = tree.add(new, i)
        status = "reached" if arrived else "advanced"
        if arrived or not greedy:
            return status, i


def rrt_connect(checker: PoseChecker, starts: np.ndarray, goals: np.ndarray, *,
                bounds: np.ndarray, rng: np.random.Generator, iterations: int = 4000,
                step: float = 0.3, time_limit: float = np.inf, passage_bias: float = 0.3,
                free_bias: float = 0.5) -> SearchOutcome:
    """Bidirectional RRT from any of ``starts`` to any of ``goals`` (both ``(K, 3)``,
    assumed valid).

    Parameters
    ----------
    checker : PoseChecker
    starts, goals : ndarray, shape (K, 3)
    bounds : ndarray, shape (2, 2)
        ``[[xmin, ymin], [xmax, ymax]]`` of the sampled positions, m.
    rng : numpy.random.Generator
    iterations : int
        Budget: samples drawn.
    step : float
        Largest robot displacement per tree edge, m.
    time_limit : float
        Wall-clock cap, s.
    passage_bias : float
        Probability that a sample puts a crossable obstacle under the sheet, clear of the
        robots (:meth:`PoseChecker.passage_sample`); such samples are connected greedily.
    free_bias : float
        Probability that a sample is drawn in the free part of a heading slice
        (:meth:`PoseChecker.free_sample`; the rest are uniform in ``bounds``).

    Returns
    -------
    SearchOutcome
    """
    if not len(starts) or not len(goals):
        return SearchOutcome(None, 0, False)
    t0 = time.perf_counter()
    a, b = _Tree(starts), _Tree(goals)
    forward = True
    # Try the straight connection of each start to the goal at the nearest heading first
    # (cheap: invalid motions fail at the first coarse check).
    for i in range(len(starts)):
        dpsi = np.abs(np.angle(np.exp(1j * (goals[:, 2] - starts[i, 2]))))
        dist = np.hypot(*(goals[:, :2] - starts[i, :2]).T) + checker.radius * dpsi
        j = int(np.argmin(dist))
        g = goals[j].copy()
        g[2] = starts[i, 2] + float(np.angle(np.exp(1j * (g[2] - starts[i, 2]))))
        if checker.motion_valid(starts[i], g):
            return SearchOutcome(np.array([starts[i], g]), 0, False, j)
    lo, hi = bounds
    for it in range(1, iterations + 1):
        if time.perf_counter() - t0 > time_limit:
            return SearchOutcome(None, it, True)
        u = rng.random()
        q = checker.passage_sample(rng) if u < passage_bias else None
        greedy = q is not None
        if q is None and u < passage_bias + free_bias:
            q = checker.free_sample(rng)
        if q is None:
            q = np.array([*rng.uniform(lo, hi), rng.uniform(-np.pi, np.pi)])
        if not checker.valid(q[None])[0]:
            continue
        status, i = _extend(a, q, checker, step, greedy=greedy)
        if status == "trapped":
            a, b, forward = b, a, not forward
            continue
        status2, j = _extend(b, a.nodes[i], checker, step, greedy=True)
        if status2 == "reached":
            pa, pb = a.branch(i), b.branch(j)
            path = np.concatenate([pa, pb[::-1][1:]])
            goal_root = int(b.root[j])
            if not forward:
                path, goal_root = path[::-1], int(a.root[i])
            return SearchOutcome(_unwrap(path), it, False, goal_root)
        a, b, forward = b, a, not forward
    return SearchOutcome(None, iterations, False)


def _unwrap(path: np.ndarray) -> np.ndarray:
    out = path.copy()
    out[:, 2] = np.unwrap(out[:, 2])
    return out


def shortcut(checker: BodyChecker, path: np.ndarray, rng: np.random.Generator,
             rounds: int = 60, passes: int = 3) -> np.ndarray:
    """Shorten ``path`` (every edge turning by at most pi) by replacing sub-paths with
    straight SE(2) motions where valid (and turning by at most pi):
    a greedy pass from the start, then ``rounds`` random pairs; repeated ``passes`` times
    on the path with its edge midpoints added (so corners can be cut partway)."""
    p = _shortcut_once(checker, path, rng, rounds)
    for _ in range(passes - 1):
        mid = (p[:-1] + p[1:]) / 2
        dense = np.empty((len(p) + len(mid), 3))
        dense[0::2], dense[1::2] = p, mid
        p = _shortcut_once(checker, dense, rng, rounds)
    return p


def _shortcut_once(checker: BodyChecker, path: np.ndarray, rng: np.random.Generator,
                   rounds: int) -> np.ndarray:
    p = _unwrap(path)
    out = [p[0]]
    i = 0
    while i < len(p) - 1:                               # greedy: farthest visible vertex
        j = len(p) - 1
        while j > i + 1 and not _straight(checker, p[i], p[j]):
            j -= 1
        out.append(p[j])
        i = j
    p = np.asarray(out)
    for _ in range(rounds):
        if len(p) < 3:
            break
        i, j = sorted(rng.choice(len(p), 2, replace=False))
        if j - i < 2:
            continue
        if _straight(checker, p[i], p[j]):
            p = np.concatenate([p[:i + 1], p[j:]])
    return _unwrap(p)


def _straight(checker: BodyChecker, a: np.ndarray, b: np.ndarray) -> bool:
    """Can the straight motion from ``a`` to ``b`` replace the path between them? It must
    be valid and turn by at most pi (paths are unwrapped edge by edge, which would turn a
    larger turn the other way)."""
    return abs(float(b[2] - a[2])) <= np.pi and checker.motion_valid(a, b)
