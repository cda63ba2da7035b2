"""The SE(2) search run by OMPL, the Open Motion Planning Library (Sucan, Moll & Kavraki
2012; PyPI ``ompl``, BSD-3-Clause), on taut's own validity checker.

One formation's poses ``(x, y, psi)`` form OMPL's ``SE2StateSpace`` with the same position
bounds as taut's own search; states are valid by
:meth:`~taut.plan.se2._space.PoseChecker.valid` and motions by
:meth:`~taut.plan.se2._space.PoseChecker.motion_valid` (a ``MotionValidator`` subclass,
so OMPL's collision-free motions are exactly the ones taut proves valid per interval).
The distance is taut's ``|dp| + R |dpsi|`` (the SO(2) subspace weighted by the formation's
radius ``R``), so OMPL's range is the same largest robot displacement per tree edge as
taut's own RRT-Connect (``STEP``). Every valid heading at the start and at the goal is a
start state and a goal state. The path is simplified by OMPL's ``PathSimplifier`` (one
deterministic round: shortcuts, better goal, B-spline smoothing, vertex reduction).

Planners (``plan(..., search=...)``):

``"ompl-rrtconnect"``
    ``og.RRTConnect`` (Kuffner & LaValle 2000), stops at the first solution.
``"ompl-rrtstar"``
    ``og.RRTstar`` (Karaman & Frazzoli 2011), path-length objective; anytime: it uses the
    whole iteration budget (or the time cap) and returns the best path.
``"ompl-prm"``
    ``og.PRM`` (Kavraki et al. 1996), stops at the first solution.

The iteration budget counts evaluations of the planner's termination condition (one per
iteration of the planner's main loop, so one sample each for the RRTs).

Seeding (what is and is not reproducible): OMPL's planners draw from ``ompl::RNG``
objects, each seeded when it is *constructed* from one process-wide seed generator.
``ompl.util.RNG.setSeed(s)`` re-seeds that generator even after seeds were handed out
(OMPL then logs an error, silenced here), so this module calls it with a seed drawn from
taut's seeded ``numpy`` generator immediately before building each problem: the
samplers, nearest-neighbour structures and the simplifier built afterwards get the same
seeds in every process, whatever ran before. Reproducible for a given ``seed`` and
``iterations`` (unless the wall-clock cap stops a search): ``"ompl-rrtconnect"`` and
``"ompl-rrtstar"`` plans, bit for bit. Not reproducible: ``"ompl-prm"`` (OMPL's PRM grows
its roadmap in wall-clock slices and looks for a solution in a second thread, so where it
stops depends on timing); and any run while another thread builds OMPL objects (the seed
generator is shared). The per-instance ``RNG(localSeed)`` constructor cannot reach the
planners' internal generators, so the process-wide re-seed is the tightest control the
Python bindings offer.

Requires the optional extra ``plan-ompl`` (``pip install 'taut[plan-ompl]'``).
"""

from __future__ import annotations

import inspect
import time
from collections.abc import Callable
from typing import Any, Literal

import numpy as np

from ...errors import InvalidInputError
from ._rrt import SearchOutcome, rrt_connect
from ._space import PoseChecker
from .._tol import MIN_ROTATION_WEIGHT

__all__ = ["OMPL_SEARCHES", "Search", "SEARCHES", "engine", "ompl_search", "unwrap_shortest"]

#: Largest robot displacement per tree edge, m: the default of taut's own RRT-Connect, read
#: from its signature so that both libraries grow trees with the same range.
STEP = float(inspect.signature(rrt_connect).parameters["step"].default)

#: Iterations of one PRM roadmap-growing chunk (expansion chunks are half as long).
PRM_CHUNK = 100
#: Wall-clock time of PRM's query (connecting start and goal to the roadmap and searching
#: it, while OMPL keeps growing the roadmap), s.
PRM_QUERY_TIME = 0.2

Search = Literal["auto", "lattice", "rrtconnect", "ompl-rrtconnect", "ompl-rrtstar",
                 "ompl-prm"]

#: Every value of ``plan(..., search=...)``: ``"auto"`` (the lattice, then taut's own
#: RRT-Connect), the lattice alone, taut's own RRT-Connect, and the OMPL planners.
SEARCHES: tuple[str, ...] = ("auto", "lattice", "rrtconnect", "ompl-rrtconnect",
                             "ompl-rrtstar", "ompl-prm")
#: The searches run by OMPL and the OMPL planner class name of each.
OMPL_SEARCHES = {"ompl-rrtconnect": "RRTConnect", "ompl-rrtstar": "RRTstar", "ompl-prm": "PRM"}


def _modules() -> tuple[Any, Any, Any]:
    """``ompl.base``, ``ompl.geometric``, ``ompl.util`` (a TautError when not installed)."""
    try:
        from ompl import base as ob, geometric as og, util as ou
    except ImportError as exc:
        raise InvalidInputError("search", "the OMPL searches need the optional extra "
                                "plan-ompl (pip install 'taut[plan-ompl]'): "
                                f"{exc}") from None
    return ob, og, ou


def unwrap_shortest(path: np.ndarray) -> np.ndarray:
    """Headings of ``path`` (K, 3) unwrapped along OMPL's SO(2) interpolation: each step
    turns the short way, by at most pi (exactly pi keeps the sign of the raw difference,
    as ``SO2StateSpace::interpolate`` does).

    Examples
    --------
    >>> unwrap_shortest(np.array([[0, 0, 3.0], [1, 0, -3.0]]))[:, 2].round(4).tolist()
    [3.0, 3.2832]
    """
    out = np.array(path, dtype=float)
    out[:, 2] = np.unwrap(out[:, 2])
    return out


def _array(s: Any) -> np.ndarray:
    return np.array([s.getX(), s.getY(), s.getYaw()])


class _Problem:
    """One OMPL problem: space, space information, validity on ``checker``."""

    def __init__(self, checker: PoseChecker, bounds: np.ndarray, seed: int) -> None:
        ob, og, ou = self.ob, self.og, self.ou = _modules()
        ou.setLogLevel(ou.LOG_NONE)             # the re-seed below logs an error
        ou.RNG.setSeed(int(seed))
        self.checker = checker
        space = self.space = ob.SE2StateSpace()
        b = ob.RealVectorBounds(2)
        for i in range(2):
            b.setLow(i, float(bounds[0, i]))
            b.setHigh(i, float(bounds[1, i]))
        space.setBounds(b)
        # the SE(2) distance is |dp| + R |dpsi|
        space.setSubspaceWeight(1, max(checker.radius, MIN_ROTATION_WEIGHT))
        si = self.si = ob.SpaceInformation(space)
        si.setStateValidityChecker(self._valid)
        self.motion = _motion_validator(ob, si, checker)
        si.setMotionValidator(self.motion)
        si.setup()

    def _valid(self, s: Any) -> bool:
        return bool(self.checker.valid(_array(s)[None])[0])

    def state(self, q: np.ndarray) -> Any:
        s = self.space.allocState()
        s.setXY(float(q[0]), float(q[1]))
        s.setYaw(float(np.angle(np.exp(1j * q[2]))))
        return s


def _motion_validator(ob: Any, si: Any, checker: PoseChecker) -> Any:
    """A ``MotionValidator`` that checks OMPL's SE(2) interpolation (heading the short
    way) with :meth:`PoseChecker.motion_valid`."""

    class TautMotionValidator(ob.MotionValidator):
        def checkMotion(self, s1: Any, s2: Any) -> bool:
            ab = unwrap_shortest(np.stack([_array(s1), _array(s2)]))
            return bool(checker.motion_valid(ab[0], ab[1]))

    return TautMotionValidator(si)


def ompl_search(name: str, checker: PoseChecker, starts: np.ndarray, goals: np.ndarray, *,
                bounds: np.ndarray, rng: np.random.Generator, iterations: int,
                time_limit: float = np.inf) -> SearchOutcome:
    """Run OMPL planner ``name`` (a key of :data:`OMPL_SEARCHES`) from any of ``starts``
    to any of ``goals`` (both ``(K, 3)``, valid) and simplify the path.

    Parameters
    ----------
    name : str
    checker : PoseChecker
    starts, goals : ndarray, shape (K, 3)
    bounds : ndarray, shape (2, 2)
        ``[[xmin, ymin], [xmax, ymax]]`` of the sampled positions, m.
    rng : numpy.random.Generator
        Source of the OMPL seed of this run (module docstring).
    iterations : int
        Budget: evaluations of the termination condition (planner iterations).
    time_limit : float
        Wall-clock cap, s (the search and the simplification).

    Returns
    -------
    SearchOutcome
        The simplified path (headings unwrapped), or None.
    """
    seed = int(rng.integers(1, 2**31 - 1))
    if not len(starts) or not len(goals):
        return SearchOutcome(None, 0, False)
    t0 = time.perf_counter()
    pb = _Problem(checker, bounds, seed)
    ob, og = pb.ob, pb.og
    if name == "ompl-prm":
        goals = goals[[_least_turn(starts, goals)]]
    pdef = ob.ProblemDefinition(pb.si)
    for q in starts:
        pdef.addStartState(pb.state(q))
    goal = ob.GoalStates(pb.si)
    for q in goals:
        goal.addState(pb.state(q))
    pdef.setGoal(goal)
    planner = getattr(og, OMPL_SEARCHES[name])(pb.si)
    if name != "ompl-prm":
        planner.setRange(STEP)
    planner.setProblemDefinition(pdef)
    planner.setup()
    budget = _Budget(iterations, t0, time_limit)
    if name == "ompl-prm":
        _solve_prm(ob, planner, pdef, budget)
    else:
        planner.solve(ob.PlannerTerminationCondition(budget.stop))
    if not pdef.hasExactSolution():
        return SearchOutcome(None, budget.used, budget.timed_out)
    path = pdef.getSolutionPath()
    if not budget.expired():
        simplifier = og.PathSimplifier(pb.si, goal)
        simplifier.simplify(path, ob.plannerAlwaysTerminatingCondition(), True)
    out = unwrap_shortest(np.array([_array(s) for s in path.getStates()]))
    dist = np.linalg.norm(goals[:, :2] - out[-1, :2], axis=1) + np.abs(
        np.angle(np.exp(1j * (goals[:, 2] - out[-1, 2]))))
    return SearchOutcome(out, budget.used, budget.timed_out, int(np.argmin(dist)))


class _Budget:
    """Termination by iteration count (evaluations of :meth:`stop`) or wall clock."""

    def __init__(self, iterations: int, t0: float, time_limit: float) -> None:
        self.iterations, self.t0, self.time_limit = int(iterations), t0, float(time_limit)
        self.count = 0
        self.timed_out = False

    @property
    def used(self) -> int:
        return min(self.count, self.iterations)

    def expired(self) -> bool:
        if time.perf_counter() - self.t0 > self.time_limit:
            self.timed_out = True
        return self.timed_out

    def stop(self) -> bool:
        self.count += 1
        return self.expired() or self.count > self.iterations


def _least_turn(starts: np.ndarray, goals: np.ndarray) -> int:
    """Index of the goal state needing the least turn from any start state."""
    d = np.abs(np.angle(np.exp(1j * (goals[:, 2][:, None] - starts[:, 2][None]))))
    return int(np.argmin(d.min(axis=1)))


def _solve_prm(ob: Any, planner: Any, pdef: Any, budget: _Budget) -> None:
    """Grow PRM's roadmap under the iteration budget, in this thread (grow and expand
    2:1 in chunks of ``PRM_CHUNK`` iterations, as OMPL's own loop does by time), then
    query it with ``PRM.solve`` under a C++ wall-clock condition of ``PRM_QUERY_TIME``
    (started once the start and goal milestones are in the roadmap).

    ``PRM.solve`` checks for a solution in a second thread; a Python termination
    condition (or a goal state added from that thread, which runs the Python motion
    validator) would wait there for the interpreter lock that the joining main thread
    holds. Hence the roadmap is grown before the query, the query's condition is pure
    C++, and the goal is one state (the others would be added from that thread).
    """
    grow = True
    while not budget.expired() and budget.count < budget.iterations:
        chunk = _Budget(min((2 if grow else 1) * PRM_CHUNK, budget.iterations - budget.count),
                        budget.t0, budget.time_limit)
        ptc = ob.PlannerTerminationCondition(chunk.stop)
        (planner.growRoadmapPtc if grow else planner.expandRoadmapPtc)(ptc)
        budget.count += max(chunk.used, 1)
        budget.timed_out |= chunk.timed_out
        grow = not grow
    # The first call only adds the start and goal milestones (its condition, already
    # true, stops the roadmap growth and the solution check); the second searches.
    planner.solve(ob.plannerAlwaysTerminatingCondition())
    pdef.clearSolutionPaths()
    left = budget.time_limit - (time.perf_counter() - budget.t0)
    planner.solve(ob.timedPlannerTerminationCondition(float(min(PRM_QUERY_TIME, max(left, 0.0)))))


def engine(search: str) -> Callable[..., SearchOutcome] | None:
    """The sampling search of ``plan(..., search=...)`` for a name of :data:`SEARCHES`
    (validated by :func:`taut.plan._options.plan_options`; None: taut's own RRT-Connect,
    also the one ``"auto"`` and ``"lattice"`` name); raises InvalidInputError when OMPL is
    not installed."""
    if search in ("auto", "lattice", "rrtconnect"):
        return None
    _modules()

    def run(checker: PoseChecker, starts: np.ndarray, goals: np.ndarray,
            **kw: Any) -> SearchOutcome:
        return ompl_search(search, checker, starts, goals, **kw)

    return run
