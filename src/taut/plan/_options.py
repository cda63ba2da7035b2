"""Options of the planner and of a plan's robustness analysis: every accepted range, defined
once, and the one validation of each set of options.

:func:`taut.plan.plan` validates its options with :func:`plan_options` and
:func:`taut.plan.plan_robustness` with :func:`robustness_options`, once per call, before
any work; the command line (``taut plan``) validates with the same functions (naming the
command-line option in its one-line error) and then runs the planner on the validated
options. Errors are :class:`~taut.errors.InvalidInputError` naming the keyword argument.
The accepted ranges are constants of :mod:`taut.plan._tol` (``MAX_SHEET_MARGIN_M``,
``MAX_TIME_BUDGET_S``, ``MAX_ITERATIONS``, ``MIN_SPACING_M``, ``MAX_SPACING_M``,
``MAX_POSITION_ERROR_M``, ``MAX_TRIALS``, ``MAX_CORRELATION_S``), where the formation
designers and :func:`~taut.plan.checks.verify.verify_motion` read the same margin limit.

Lengths in metres, times in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, cast

from .._validate import as_bounded, as_choice, as_count, as_flag
from ..errors import InvalidInputError
from . import _tol
from ._tol import (MAX_CORRELATION_S, MAX_ITERATIONS, MAX_POSITION_ERROR_M, MAX_SHEET_MARGIN_M,
    MAX_SPACING_M, MAX_TIME_BUDGET_S, MAX_TRIALS, MIN_SPACING_M)
from .se2._ompl import SEARCHES, Search, engine
from .se2._search import SearchBudget

__all__ = ["PlanOptions", "RobustnessOptions", "plan_options", "robustness_options",
           "METHODS", "BASELINES", "NOISES", "LinearScreen", "LINEAR_SCREEN"]

#: Planning methods of :func:`taut.plan.plan` (its ``method``).
METHODS: tuple[str, ...] = ("se2", "roadmap", "algorithm2")
#: Bypass-only baselines of :func:`taut.plan.plan` (its ``baseline``).
BASELINES: tuple[str, ...] = ("se2", "disc")
#: Robot position error models of the robustness analysis (its ``noise``).
NOISES: tuple[str, ...] = ("disc", "gaussian")

Method = Literal["se2", "roadmap", "algorithm2"]
Baseline = Literal["se2", "disc"]
Noise = Literal["disc", "gaussian"]

@dataclass(frozen=True)
class PlanOptions:
    """Validated options of :func:`taut.plan.plan` (built by :func:`plan_options`).

    Attributes
    ----------
    method : {"se2", "roadmap", "algorithm2"}
    baseline : {"se2", "disc"} or None
    straight_crossings : bool
    sheet_margin : float
        m.
    budget : SearchBudget
        Iterations, seed, optional time cap (s) and lattice spacing (m) of the SE(2)
        search.
    search : str
        One of :data:`~taut.plan.se2._ompl.SEARCHES`.
    """

    method: Method
    baseline: Baseline | None
    straight_crossings: bool
    sheet_margin: float
    budget: SearchBudget
    search: Search


def plan_options(*, method: Any = "se2", baseline: Any = None,
                 straight_crossings: Any = True, sheet_margin: Any = _tol.SHEET_MARGIN,
                 time_budget: Any = None, iterations: Any = 3000, seed: Any = 0,
                 search: Any = "auto", spacing: Any = 0.05) -> PlanOptions:
    """Validate the options of :func:`taut.plan.plan` (see there for their meaning).

    Returns
    -------
    PlanOptions

    Raises
    ------
    InvalidInputError
        An option out of its range (the field names the keyword argument), an unknown
        choice, or an OMPL search without the optional extra ``plan-ompl``.
    """
    method = as_choice(method, METHODS, "method")
    if baseline is not None:
        baseline = as_choice(baseline, BASELINES, "baseline")
    straight = as_flag(straight_crossings, "straight_crossings")
    margin = as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_MARGIN_M, "m", positive=False)
    cap = None if time_budget is None else as_bounded(time_budget, "time_budget",
                                                      MAX_TIME_BUDGET_S, "s")
    iterations = as_count(iterations, "iterations", minimum=1, maximum=MAX_ITERATIONS)
    seed = as_count(seed, "seed", minimum=0)
    spacing = as_bounded(spacing, "spacing", MAX_SPACING_M, "m")
    if spacing < MIN_SPACING_M:
        raise InvalidInputError("spacing", f"{spacing:g} is below the accepted range "
                                           f"{MIN_SPACING_M:g} m")
    search = as_choice(search, SEARCHES, "search")
    engine(search)                                  # OMPL installed when it is named
    budget = SearchBudget(iterations=iterations, seed=seed, time_budget=cap, spacing=spacing)
    return PlanOptions(cast(Method, method), cast("Baseline | None", baseline), straight,
                       margin, budget, cast(Search, search))


@dataclass(frozen=True)
class RobustnessOptions:
    """Validated options of :func:`taut.plan.plan_robustness` (built by
    :func:`robustness_options`).

    Attributes
    ----------
    sigma : float
        Robot position error, m.
    trials : int
    noise : {"disc", "gaussian"}
    seed : int
    correlation : float
        s.
    """

    sigma: float
    trials: int
    noise: Noise
    seed: int
    correlation: float


def robustness_options(sigma: Any = _tol.POSITION_ACCURACY, trials: Any = 200, *,
                       noise: Any = "disc", seed: Any = 0, correlation: Any = 1.0
                       ) -> RobustnessOptions:
    """Validate the options of :func:`taut.plan.plan_robustness` (see there).

    Raises
    ------
    InvalidInputError
        An option out of its range or an unknown ``noise``.
    """
    return RobustnessOptions(
        as_bounded(sigma, "sigma", MAX_POSITION_ERROR_M, "m", positive=False),
        as_count(trials, "trials", minimum=1, maximum=MAX_TRIALS),
        cast(Noise, as_choice(noise, NOISES, "noise")),
        as_count(seed, "seed", minimum=0),
        as_bounded(correlation, "correlation", MAX_CORRELATION_S, "s"))



@dataclass(frozen=True)
class LinearScreen:
    """The linearised robustness screen of the planner's formation admission (issue 28):
    before the seeded Monte Carlo of a formation's rest state under robot position error
    (:func:`~taut.plan.formations._squeeze_robust.tolerates`), the first-order prediction
    through the state's ``jacobian`` (:func:`taut.sheet.object_covariance`) rejects a
    state whose object height above its least height, or whose allowed shift, is below
    ``sigmas`` predicted standard deviations. It only rejects (what passes is sampled: the
    sampling decides), and is sized so that it rejects only what the sampling rejects too
    (measured: ``bench/bench_plan_screen.py``).

    Attributes
    ----------
    enabled : bool
        False: every candidate is sampled.
    sigmas : float
        Predicted standard deviations (dimensionless) a margin must exceed.
    """

    enabled: bool = True
    sigmas: float = 1.0


#: The screen the planner uses (the one place it is set; benchmarks replace it to measure
#: the planner without it).
LINEAR_SCREEN = LinearScreen()
