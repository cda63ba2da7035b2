"""Front end of the planners: :func:`plan` (planning paper Sec. IV, Fig. 4, and issue 14).

Methods (one private module each):

``"se2"`` (default)
    The team is a rigid body in SE(2) per formation of a small library
    (:mod:`taut.plan.formations.library`: the compact one, the narrow one, per obstacle-height class
    the optimal crossing formation of eqs. 11-15, and a squeezed one where passages are
    too narrow for all of them). The lattice search (:mod:`taut.plan.se2._lattice`) searches
    every formation at once with any number of in-place formation changes; where it finds
    nothing, a seeded RRT-Connect searches each formation and pairs with one change
    (:mod:`taut.plan.se2._search`), or OMPL does (``search=``). Low obstacles pass under the sheet
    between any two robots at any heading. When no SE(2) candidate verifies, the
    disc-model roadmap plan is tried too; the SE(2) bypass baseline's plan is always a
    candidate (the faster one is returned), so the planner succeeds wherever either
    baseline does and is never slower than the SE(2) bypass baseline. Failures carry a
    certificate (status ``refuted``) or say the budget ran out (``budget_exhausted``).
``"roadmap"``
    The disc-model roadmap of :func:`~taut.plan.roadmap.route.find_route` with Algorithm 2 and
    straight offset crossings (the planner of issue 4).
``"algorithm2"``
    The same roadmap with the paper's Algorithm 2 only (paper-faithful mode).

Baselines (``baseline=``): ``"se2"`` the same SE(2) search with crossing disabled (same
library, searches and budget); ``"disc"`` the disc-model bypass (the formation is a disc
covering every heading, routed on the visibility roadmap; the baseline of issue 4). Both
use the same timing and verification as the crossing planner.

:func:`plan` validates its options once (:func:`taut.plan._options.plan_options`) and
:func:`run_plan` dispatches them to the engines; everything below calls engines, never a
public entry that validates again.
"""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np

from . import _tol
from .se2._ompl import Search, engine
from .se2._lattice import MAX_NODES, lattice_search
from .se2._search import SE2Search, SearchBudget, search_se2
from .se2._space import PoseChecker
from .se2._motion import Piece, sample_pieces
from .checks.certificate import _find_certificate
from .formations.optimal import Formation
from .formations.library import Library, _diagnosis, _with_squeezed, library
from ._options import Baseline, Method, PlanOptions, plan_options
from .result import PlanResult, _summary, attempt, failure, relabel
from .roadmap.route import crossable
from .checks.verify import _verify_motion
from .world import Scenario
from .._validate import require_instance

__all__ = ["plan"]


def _roadmap(scenario: Scenario, straight: bool, sheet_margin: float, planner: str,
             library: Library) -> PlanResult:
    """The disc-model roadmap planner of issue 4 (see ``method="roadmap"``)."""
    world = scenario.world
    compact, crossing, notes = library
    best = attempt(scenario, compact, allow_crossing=False, planner="disc",
                   sheet_margin=sheet_margin)
    reasons = list(notes) if best.success else [f"bypassing: {best.message}", *notes]
    candidates: list[Formation] = []
    if any(crossable(scenario, compact, o, straight=straight) is None for o in world.obstacles):
        candidates.append(compact)
    crossing = [f for f in crossing if f.kind == "crossing"]
    candidates += crossing
    combos: list = list(candidates)
    if crossing:
        combos.append([compact, *crossing])
    for f in combos:
        r = attempt(scenario, f, allow_crossing=True, planner=planner,
                    straight_crossings=straight, sheet_margin=sheet_margin)
        if r.success and any(c.kind == "straight" for c in r.crossings):
            # The route search does not cost the turn into a straight crossing's heading;
            # Algorithm 2 alone (a subset of the edges) may be faster in time.
            r2 = attempt(scenario, f, allow_crossing=True, planner=planner,
                         straight_crossings=False, sheet_margin=sheet_margin)
            if r2.success and r2.duration < r.duration:
                r = r2
        if not r.success:
            if isinstance(f, Formation):
                reasons.append(f"crossing with the object at {f.object_height:.3g} m: "
                               f"{r.message}")
            continue
        rtol = _tol.DURATION_RTOL
        if not best.success or r.duration <= best.duration * (1 + rtol):
            if not best.success or r.duration < best.duration * (1 - rtol) or r.crossed:
                best = r
    if best.success:
        return relabel(best, planner)
    return failure(scenario, "; ".join(dict.fromkeys(reasons)) or "no plan", planner)


def _finish_se2(scenario: Scenario, pieces: list[Piece], planner: str, sheet_margin: float
                ) -> PlanResult:
    """Sample, verify and package one SE(2) candidate."""
    m = sample_pieces(scenario, pieces)
    if m.message is not None:
        return failure(scenario, f"plan rejected: {m.message}", planner, "unverified")
    check = _verify_motion(scenario, m.robots, m.object, sheet_margin)
    if not check.success:
        return failure(scenario, f"plan rejected by verification: {check.message}", planner,
                       "unverified")
    import shapely
    hulls = shapely.convex_hull(shapely.multipoints(m.robots))
    crossed = tuple(o.id for o in scenario.world.obstacles
                    if shapely.intersects(hulls, o.geometry).any())
    bypassed = tuple(o.id for o in scenario.world.obstacles if o.id not in crossed)
    forms = tuple(dict.fromkeys(p.formation for p in pieces))
    main = max(forms, key=lambda f: f.object_height)
    return PlanResult(True, "ok", _summary(m.duration, m.path_length, crossed), m.times,
                      m.robots, check.object, check.taut, m.heading, crossed, bypassed,
                      m.path_length, m.duration, main, (), planner, check, forms,
                      sheet_margin=sheet_margin, scenario=scenario)


def _lattice(scenario: Scenario, forms: list[Formation], allow_crossing: bool,
             budget: SearchBudget, planner: str, sheet_margin: float
             ) -> tuple[PlanResult | None, str]:
    """The lattice search over every formation (:mod:`taut.plan.se2._lattice`): its verified
    plan, or None and what it found."""
    checkers = [PoseChecker(scenario, f, allow_crossing=allow_crossing) for f in forms]
    lat = lattice_search(scenario, forms, checkers, spacing=budget.spacing,
                         expansions=MAX_NODES, rng=np.random.default_rng(budget.seed))
    where = (f"a lattice of {lat.spacing:.3g} m and {lat.headings} headings over "
             f"{len(forms)} formation(s) with any number of changes")
    refused = ("; changes refused by the quasi-static model: "
               + "; ".join(lat.refused_changes)) if lat.refused_changes else ""
    if lat.pieces is None:
        return None, f"no path on {where}{refused}"
    r = _finish_se2(scenario, lat.pieces, planner, sheet_margin)
    if r.success:
        return replace(r, search="lattice"), ""
    return None, f"the path found on {where} failed verification: {r.message}"


def _se2(scenario: Scenario, *, allow_crossing: bool, sheet_margin: float,
         budget: SearchBudget, planner: str, library: Library,
         search: Search = "auto") -> PlanResult:
    """One SE(2) search (crossing planner or its bypass baseline) and its best plan."""
    compact, others, notes = library
    # A squeezed formation joins where passages are too narrow for all the others; the
    # search weighs time in it, so it is used only where it is needed.
    forms = _with_squeezed(scenario, [compact, *others], allow_crossing, sheet_margin)
    lattice_note = ""
    if search in ("auto", "lattice"):
        found_lattice, lattice_note = _lattice(scenario, forms, allow_crossing, budget,
                                               planner, sheet_margin)
        if found_lattice is not None:
            return found_lattice
    results: list[PlanResult] = []

    def accept(pieces: list[Piece]) -> bool:
        results.append(_finish_se2(scenario, pieces, planner, sheet_margin))
        return results[-1].success

    if search == "lattice":
        found = SE2Search()
    else:
        found = search_se2(scenario, forms, allow_crossing=allow_crossing, budget=budget,
                           accept=accept, engine=engine(search))
    good = [r for r in results if r.success]
    if good:
        who = "rrtconnect" if search == "auto" else search
        return replace(min(good, key=lambda r: r.duration), search=who)
    cert = _find_certificate(scenario)
    if cert is not None:
        return failure(scenario, cert.message, planner, "refuted", cert)
    rejected = list(dict.fromkeys(r.message for r in results))
    tried = "; ".join([*found.notes, *notes, *rejected])
    if results and not found.timed_out and len(results) == len(found.notes):
        return failure(scenario, f"every candidate failed verification: {tried}", planner,
                       "unverified")
    if search == "lattice":
        head = "not found on the lattice"
    else:
        cap = (f"the time cap of {budget.time_budget:g} s" if found.timed_out
               else f"{budget.iterations} samples per run, {found.iterations} of "
                    f"{budget.total_samples} in all")
        head = f"not found within the budget ({cap}; seed {budget.seed})"
    searched = ("searched " + ", ".join(f"{f.kind} (object at {f.object_height:.3g} m)"
                                        for f in forms)
                + (f" alone and {found.pairs} formation pair(s) with one change, "
                   if search != "lattice" else ", ")
                + ("crossing low obstacles" if allow_crossing else "bypassing only"))
    return failure(scenario, f"{head}: " + "; ".join(
        x for x in (searched, lattice_note, tried,
                    _diagnosis(scenario, forms, allow_crossing)) if x),
                   planner, "budget_exhausted")


def plan(scenario: Scenario, *, method: Method = "se2",
         baseline: Baseline | None = None, straight_crossings: bool = True,
         sheet_margin: float = _tol.SHEET_MARGIN, time_budget: float | None = None,
         iterations: int = 3000, seed: int = 0, search: Search = "auto",
         spacing: float = 0.05) -> PlanResult:
    """Plan the transport of the object from ``scenario.start`` to ``scenario.goal``.

    Parameters
    ----------
    scenario : Scenario
    method : {"se2", "roadmap", "algorithm2"}
        See the module docstring.
    baseline : {"se2", "disc"}, optional
        Plan with a bypass-only baseline instead (module docstring); ``method`` and
        ``straight_crossings`` are then unused.
    straight_crossings : bool
        ``method="roadmap"`` only: also allow straight offset crossings.
    sheet_margin : float
        Every robot pair stays this far inside its sheet distance, m, in [0, 1] (default
        0.01 m: robots off by at most 5 mm each never tear the sheet).
    time_budget : float or None
        Optional wall-clock safety cap of each sampling search, s, at most 3600 (default
        None: no cap). What decides success is the lattice (its spacing) and
        ``iterations``, so the answer does not depend on the machine's load; a cap that
        stops a search is reported in the message, and then the answer may depend on the
        load. The lattice search is not interrupted: it is bounded by its node count
        (``MAX_NODES``).
    iterations : int
        Samples per RRT-Connect run of the sampling search (its deterministic budget),
        1 to 200000.
    seed : int
        Seed of the SE(2) search (>= 0): plans are reproducible for a given seed and
        ``iterations`` (unless the optional time cap stops a search).
    search : {"auto", "lattice", "rrtconnect", "ompl-rrtconnect", "ompl-rrtstar", "ompl-prm"}
        Who searches SE(2) (``method="se2"`` and ``baseline="se2"``). ``"lattice"``: A*
        over a lattice of poses of every formation at once, with any number of formation
        changes (:mod:`taut.plan.se2._lattice`; deterministic, the fastest lattice path,
        resolution-complete at ``spacing``); ``"rrtconnect"``: taut's own seeded
        RRT-Connect per formation and formation pair (narrow passages below the lattice's
        resolution); ``"auto"`` (default): the lattice, then RRT-Connect where it finds
        nothing. ``"ompl-*"``: OMPL's RRT-Connect / RRT* / PRM in place of taut's
        RRT-Connect, on the same validity checker, formations, bounds and verification
        (optional extra ``plan-ompl``; seeding in :mod:`taut.plan.se2._ompl`).
    spacing : float
        Lattice spacing, m, in [0.005, 1] (the headings are spaced so that a heading step
        moves the farthest robot about as far).

    The accepted ranges are defined once, in :mod:`taut.plan._tol`, and validated by
    :func:`taut.plan._options.plan_options`.

    Returns
    -------
    PlanResult
        ``success`` is True only for a plan that passed verification.

    Raises
    ------
    InvalidInputError
        An option out of its range or an unknown choice.
    PlanningError
        The team cannot hold the object at all.

    Examples
    --------
    >>> from taut.io.plan_scenario import load_plan_scenario      # doctest: +SKIP
    >>> r = plan(load_plan_scenario("examples/plan/paper_corridor.yaml"))  # doctest: +SKIP
    >>> r.success, r.status, r.crossed                             # doctest: +SKIP
    (True, 'ok', ('1', '2'))
    """
    require_instance(scenario, Scenario, "scenario")
    return run_plan(scenario, plan_options(
        method=method, baseline=baseline, straight_crossings=straight_crossings,
        sheet_margin=sheet_margin, time_budget=time_budget, iterations=iterations,
        seed=seed, search=search, spacing=spacing))


def run_plan(scenario: Scenario, options: PlanOptions) -> PlanResult:
    """:func:`plan` on options validated by :func:`~taut.plan._options.plan_options` (for
    front ends that validate before loading the scenario, such as ``taut plan``):
    dispatches to the engine of the method or baseline."""
    margin = options.sheet_margin
    r = _dispatch(scenario, options)
    return r if r.success else replace(r, sheet_margin=margin)


def _dispatch(scenario: Scenario, options: PlanOptions) -> PlanResult:
    """The engine of ``options.baseline`` or ``options.method``."""
    margin, budget, search = options.sheet_margin, options.budget, options.search
    lib = library(scenario, margin)
    if options.baseline == "disc":
        return attempt(scenario, lib[0], allow_crossing=False, planner="disc",
                       sheet_margin=margin)
    if options.baseline == "se2":
        return _bypass(scenario, margin, budget, search)
    if options.method != "se2":
        return _roadmap(scenario, options.method == "roadmap" and options.straight_crossings,
                        margin, options.method, lib)
    full = budget                 # the SE(2) bypass fallback runs exactly as the baseline
    first = budget if budget.time_budget is None else replace(
        budget, time_budget=0.7 * budget.time_budget)
    best = _se2(scenario, allow_crossing=True, sheet_margin=margin, budget=first,
                planner="crossing", library=lib, search=search)
    if best.status == "refuted":
        return best
    if not best.success:
        # A fallback that makes the planner succeed wherever the disc baseline does.
        alt = _roadmap(scenario, True, margin, "crossing", lib)
        if alt.success:
            best = alt
    # The SE(2) bypass baseline's own plan (memoised: one search for the planner and the
    # baseline) is a candidate too, so the crossing planner is never slower than it: the
    # crossing search contains every bypass plan, but its lattice (more formations, so
    # another spacing and heading count), the seeded shortcutting of its path and its
    # fallbacks do not reproduce the bypass search's exactly.
    straight = float(np.linalg.norm(scenario.goal - scenario.start)) / scenario.team.speed
    if best.success and best.duration <= straight * (1 + _tol.DURATION_RTOL):
        return best               # the straight line at the team's speed: nothing is faster
    alt = _bypass(scenario, margin, full, search)
    if alt.success and (not best.success or
                        alt.duration < best.duration * (1 - _tol.DURATION_RTOL)):
        why = ("" if not best.success else
               f"; the bypass search's plan, faster than the crossing search's "
               f"{best.duration:.2f} s")
        return replace(relabel(alt, "crossing"), message=alt.message + why)
    return best


@functools.lru_cache(maxsize=32)
def _bypass(scenario: Scenario, sheet_margin: float, budget: SearchBudget,
            search: Search = "auto") -> PlanResult:
    """The SE(2) bypass search (the baseline, and the crossing planner's last fallback),
    memoised: it is deterministic for a given scenario, margin and sample budget, so the
    fallback and the baseline are one search, run once."""
    lib = library(scenario, sheet_margin)
    return _se2(scenario, allow_crossing=False, sheet_margin=sheet_margin, budget=budget,
                planner="se2-bypass", library=lib, search=search)
