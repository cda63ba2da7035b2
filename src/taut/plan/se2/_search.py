"""The SE(2) search over a library of formations (issue 14's planner, our construction).

For each formation of the library the team is a rigid body in SE(2); a seeded RRT-Connect
(:mod:`taut.plan.se2._rrt`) searches its valid poses (:mod:`taut.plan.se2._space`) from every
valid heading at the start to every valid heading at the goal, and the path is shortcut.
Low obstacles may pass under the sheet between any two robots at any heading, with turns
anywhere: Algorithm 2's turn-cross-turn is one motion among those the search can produce.

Formation changes: when no single formation reaches the goal, pairs ``(A, B)`` are tried:
states valid for both where the in-place change from ``A`` to ``B`` keeps every rule are
sampled (the robots move straight, every robot clear of walls and obstacles, the hull over
obstacles low enough for both formations); the search runs from the start to any of them
in ``A`` and on from the one reached to the goal in ``B``. The quasi-static simulation
then checks each change (:mod:`taut.plan.se2._motion`).

All candidates are deterministic for a given ``seed``: the budget that decides success is
an iteration count per search (samples drawn), independent of the machine's load; an
optional wall-clock cap for the whole search is only a safety stop (reported when it
stops the search, and then the answer may depend on the load).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ._rrt import SearchOutcome, rrt_connect, shortcut, valid_headings
from ._motion import Piece
from ._space import PoseChecker, morph_valid
from ..formations.optimal import Formation
from ..world import Scenario

__all__ = ["SearchBudget", "SE2Search", "search_se2", "MAX_PAIRS"]

#: Most formation pairs (one formation change) searched.
MAX_PAIRS = 6
#: Default total samples of one search, in units of ``SearchBudget.iterations``: room for
#: the quick rounds (a fifth of a run per formation and pair) and a few full runs, while
#: bounding the work of a failing search.
TOTAL_RUNS = 4

#: A search from starts to goals with :func:`~taut.plan.se2._rrt.rrt_connect`'s signature.
Engine = Callable[..., SearchOutcome]


@dataclass(frozen=True)
class SearchBudget:
    """Budget of the SE(2) search.

    Attributes
    ----------
    iterations : int
        Samples per RRT-Connect run.
    time_budget : float or None
        Optional wall-clock safety cap of the whole search, s (None: no cap, the search
        is deterministic for ``seed``).
    seed : int
        Seed of every random choice.
    reform_samples : int
        Formation-change states sampled per formation pair.
    total : int or None
        Samples of the whole search (every run together; default ``TOTAL_RUNS`` times
        ``iterations``): bounds the work deterministically.
    spacing : float
        Spacing of the lattice search, m (:mod:`taut.plan.se2._lattice`).
    """

    iterations: int = 3000
    time_budget: float | None = None
    seed: int = 0
    reform_samples: int = 24
    total: int | None = None
    spacing: float = 0.05

    @property
    def total_samples(self) -> int:
        """Samples the whole search may draw."""
        return self.total if self.total is not None else TOTAL_RUNS * self.iterations


@dataclass
class SE2Search:
    """Candidates found (lists of :class:`Piece`) and what the search tried."""

    candidates: list[list[Piece]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    timed_out: bool = False
    iterations: int = 0
    spent: bool = False           # the total sample budget ran out
    pairs: int = 0                # formation pairs (one change) in the search


def _bounds(scenario: Scenario) -> np.ndarray:
    fs = scenario.world.free_space
    return np.array([fs.min(axis=0), fs.max(axis=0)])


def _reform_states(scenario: Scenario, ca: PoseChecker, cb: PoseChecker,
                   rng: np.random.Generator, count: int) -> np.ndarray:
    lo, hi = _bounds(scenario)
    found: list[np.ndarray] = []
    for _ in range(40):
        q = np.column_stack([rng.uniform(lo, hi, (256, 2)), rng.uniform(-np.pi, np.pi, 256)])
        q = q[ca.valid(q)]
        if len(q):
            q = q[cb.valid(q)]
        found.extend(s for s in q if morph_valid(ca, cb, s))
        if len(found) >= count:
            break
    return np.asarray(found[:count]).reshape(-1, 3)


class _Runner:
    def __init__(self, scenario: Scenario, budget: SearchBudget, allow_crossing: bool,
                 accept: Callable[[list[Piece]], bool], engine: Engine | None = None):
        self.sc, self.budget, self.allow = scenario, budget, allow_crossing
        self.accept = accept
        self.engine = engine
        self.rng = np.random.default_rng(budget.seed)
        self.t0 = time.perf_counter()
        self.out = SE2Search()
        self.checkers: dict[int, PoseChecker] = {}
        self._ends: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def left(self) -> float:
        """Wall-clock time left under the optional cap, s (inf without one); 0 once the
        total sample budget is spent."""
        if self.out.iterations >= self.budget.total_samples:
            self.out.spent = True
            return 0.0
        if self.budget.time_budget is None:
            return np.inf
        return self.budget.time_budget - (time.perf_counter() - self.t0)

    def checker(self, f: Formation) -> PoseChecker:
        if id(f) not in self.checkers:
            self.checkers[id(f)] = PoseChecker(self.sc, f, allow_crossing=self.allow)
        return self.checkers[id(f)]

    def search(self, c: PoseChecker, starts: np.ndarray, goals: np.ndarray,
               iterations: int | None = None):
        room = self.budget.total_samples - self.out.iterations
        res = (self.engine or rrt_connect)(
            c, starts, goals, bounds=_bounds(self.sc), rng=self.rng,
            iterations=max(1, min(iterations or self.budget.iterations, room)),
            time_limit=max(self.left(), 0))
        self.out.iterations += res.iterations
        self.out.timed_out |= res.timed_out
        if res.path is None:
            return None, -1
        if self.engine is not None:             # an engine returns its simplified path
            return res.path, res.goal_index
        return shortcut(c, res.path, self.rng), res.goal_index

    def single(self, f: Formation, iterations: int | None = None) -> bool:
        c = self.checker(f)
        starts, goals = valid_headings(c, self.sc.start), valid_headings(c, self.sc.goal)
        label = f"{f.kind} formation (object at {f.object_height:.3g} m)"
        if not len(starts) or not len(goals):
            where = "start" if not len(starts) else "goal"
            self.out.notes.append(f"{label}: no valid heading at the {where}")
            return False
        path, _ = self.search(c, starts, goals, iterations)
        if path is None:
            if iterations is None:
                self.out.notes.append(f"{label}: no path within the budget")
            return iterations is not None
        if self.accept([Piece(f, path)]):
            self.out.candidates.append([Piece(f, path)])
        else:
            self.out.notes.append(f"{label}: the path found failed verification")
        return False

    def ends(self, f: Formation) -> tuple[np.ndarray, np.ndarray]:
        """Valid start and goal states of ``f`` (memoised)."""
        if id(f) not in self._ends:
            c = self.checker(f)
            self._ends[id(f)] = (valid_headings(c, self.sc.start),
                                 valid_headings(c, self.sc.goal))
        return self._ends[id(f)]

    def pair(self, fa: Formation, fb: Formation, iterations: int | None = None) -> None:
        ca, cb = self.checker(fa), self.checker(fb)
        starts, goals = self.ends(fa)[0], self.ends(fb)[1]
        if not len(starts) or not len(goals):
            return
        mids = _reform_states(self.sc, ca, cb, self.rng, self.budget.reform_samples)
        for attempt in range(4):
            if not len(mids) or self.left() <= 0:
                return
            # Alternately: from the goal side first (the mid must reach the goal in B),
            # or from the start side first.
            if attempt % 2 == 0:
                back, k = self.search(cb, goals, mids, iterations)
                if back is None:
                    return
                second = back[::-1]
                first, _ = self.search(ca, starts, second[:1], iterations)
            else:
                first, k = self.search(ca, starts, mids, iterations)
                if first is None:
                    return
                second, _ = self.search(cb, first[-1:], goals, iterations)
            if first is not None and second is not None:
                pieces = [Piece(fa, first), Piece(fa, first[-1:], fb), Piece(fb, second)]
                if self.accept(pieces):
                    self.out.candidates.append(pieces)
                    return
            mids = np.delete(mids, k, axis=0)


def search_se2(scenario: Scenario, formations: list[Formation], *, allow_crossing: bool,
               budget: SearchBudget, accept: Callable[[list[Piece]], bool],
               reform: bool = True, engine: Engine | None = None) -> SE2Search:
    """Search every formation alone, then (``reform`` and none alone succeeded) every
    ordered pair with one formation change; returns every candidate found that
    ``accept`` (the verification) accepts. ``engine`` replaces the seeded RRT-Connect and
    its shortcutting (same arguments and outcome as :func:`~taut.plan.se2._rrt.rrt_connect`,
    path already simplified; e.g. an OMPL planner, :mod:`taut.plan.se2._ompl`)."""
    run = _Runner(scenario, budget, allow_crossing, accept, engine)
    quick = max(1, budget.iterations // 5)
    pairs = []
    if reform:
        ends = {id(f): tuple(len(e) > 0 for e in run.ends(f)) for f in formations}
        pairs = [(a, b) for a in formations for b in formations
                 if a is not b and ends[id(a)][0] and ends[id(b)][1]]
        # First the pairs whose formations cannot do it alone (no goal / no start room);
        # at most MAX_PAIRS of them.
        pairs.sort(key=lambda p: (ends[id(p[0])][1], ends[id(p[1])][0]))
        pairs = pairs[:MAX_PAIRS]
    run.out.pairs = len(pairs)
    # Rounds: quick singles, quick pairs, full singles, full pairs; stop at the first
    # round that finds a verified plan.
    retry = [f for f in formations if run.left() > 0 and run.single(f, quick)]
    for stage in ("quick pairs", "singles", "pairs"):
        if run.out.candidates or run.left() <= 0:
            break
        if stage == "singles":
            for f in retry:
                if run.left() > 0:
                    run.single(f)
            continue
        for a, b in pairs:
            if run.left() > 0:
                run.pair(a, b, quick if stage == "quick pairs" else None)
    if run.left() <= 0 and not run.out.spent:
        run.out.timed_out = True
    return run.out
