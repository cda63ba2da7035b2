"""`taut plan`: transport plan with obstacle crossing for a sheet-carrying team."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .._validate import as_count
from ..errors import InvalidInputError
from ..io.serialize import plan_to_dict, robustness_to_dict, to_json
from ._paths import ANIMATION_SUFFIXES, FIGURE_SUFFIXES, JSON_SUFFIXES, output_path
from ._progress import working

__all__ = ["register", "plan_to_dict", "plan_command"]

#: Largest search budget the command accepts, s (one hour).
MAX_BUDGET_S = 3600.0
#: Largest iteration budget the command accepts (a few minutes of search per run).
MAX_ITERATIONS = 200_000
#: Most Monte Carlo trials of --robustness (each replays the whole plan).
MAX_TRIALS = 100_000


def plan_command(
    scenario: Path = typer.Argument(..., help="Planning scenario file (YAML or JSON)."),
    as_json: bool = typer.Option(False, "--json", help="Print the plan as JSON on stdout "
                                 "instead of the one-line summary."),
    out: Optional[Path] = typer.Option(None, "--out", help="Also write the plan as JSON to "
                                       "this file (.json)."),
    animate: Optional[Path] = typer.Option(None, "--animate", help="Write an animated GIF "
                                           "(.gif)."),
    baseline: bool = typer.Option(False, "--baseline",
                                  help="Bypass-only SE(2) baseline (same search, no crossing)."),
    disc_baseline: bool = typer.Option(False, "--disc-baseline",
                                       help="Bypass-only disc-model baseline."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write the summary figure "
                                        "(.png, .pdf, .svg)."),
    algorithm2: bool = typer.Option(False, "--algorithm2",
                                    help="Cross only as the paper's Algorithm 2 does (the "
                                         "obstacle passes under the object)."),
    budget: Optional[float] = typer.Option(None, "--budget", help="Optional wall-clock "
                                           "safety cap of each search, s (default: none; "
                                           "then the answer does not depend on the "
                                           "machine's load)."),
    iterations: int = typer.Option(3000, "--iterations", help="Search budget: samples per "
                                   "RRT-Connect run (deterministic for a seed)."),
    sheet_margin: float = typer.Option(0.01, "--sheet-margin",
                                       help="Robot pairs stay this far inside their sheet "
                                            "distance, m."),
    seed: int = typer.Option(0, "--seed", help="Seed of the SE(2) search."),
    search: str = typer.Option("auto", "--search",
                               help="Who searches SE(2): auto (the lattice, then "
                                    "rrtconnect), lattice (A* over every formation, "
                                    "deterministic), rrtconnect (taut's own, seeded), "
                                    "ompl-rrtconnect, ompl-rrtstar or ompl-prm (OMPL, extra "
                                    "plan-ompl)."),
    spacing: float = typer.Option(0.05, "--spacing", help="Lattice spacing of the lattice "
                                  "search, m."),
    robustness: Optional[float] = typer.Option(None, "--robustness", help="Also replay the "
                                               "plan under this robot position error, m "
                                               "(seeded Monte Carlo): failure "
                                               "probabilities."),
    trials: int = typer.Option(100, "--trials", help="Trials of --robustness."),
) -> int:
    """Plan the transport of the object from start to goal, crossing low obstacles under
    the sheet where that is faster; exit 0 with a plan, 1 when no plan exists, 2 on bad
    input."""
    from ..io.plan_scenario import load_plan_scenario
    from ..plan.planner import plan

    out = output_path(out, "--out", JSON_SUFFIXES)
    plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
    animate = output_path(animate, "--animate", ANIMATION_SUFFIXES)
    _check_options(budget, sheet_margin, seed, iterations, search, spacing,
                   baseline and disc_baseline, robustness, trials)
    sc = load_plan_scenario(scenario)
    with working("plan"):
        result = plan(sc, baseline="disc" if disc_baseline else baseline,
                      method="algorithm2" if algorithm2 else "se2", time_budget=budget,
                      iterations=iterations, sheet_margin=sheet_margin, seed=seed,
                      search=search, spacing=spacing)  # type: ignore[arg-type]  # checked
    doc = plan_to_dict(result)
    rob = None
    if robustness is not None and result.success:
        with working("robustness"):
            rob = result.robustness(robustness, trials, seed=seed)
        doc["robustness"] = robustness_to_dict(rob)
    if out is not None:
        out.write_text(to_json(doc, indent=None) + "\n", encoding="utf-8")
    if result.success and (plot is not None or animate is not None):
        from ..viz.plan import animate_plan, plot_plan
        if plot is not None:
            plot_plan(sc, result, plot)
        if animate is not None:
            animate_plan(sc, result, animate)
    _report(result, rob, doc, as_json, plot, animate)
    return 0 if result.success else 1


def _report(result, rob, doc: dict, as_json: bool, plot: Optional[Path],
            animate: Optional[Path]) -> None:
    """The plan's JSON, or its summary (and the robustness line); why figures were not
    written."""
    if as_json:
        typer.echo(to_json(doc))
    elif result.success:
        typer.echo(f"plan: {len(result.times)} samples, {result.duration:.2f} s, path "
                   f"{result.path_length:.3f} m, crossed [{', '.join(result.crossed)}], "
                   f"object at {result.object[:, 2].max():.3f} m")
        if rob is not None:
            typer.echo(f"robustness ({rob.trials} trials, {rob.sigma * 1e3:g} mm): failure "
                       f"{rob.failure_probability:.3f} (tear {rob.tear_probability:.3f}, "
                       f"drop {rob.drop_probability:.3f}, contact "
                       f"{rob.contact_probability:.3f}, collision "
                       f"{rob.collision_probability:.3f}); below the height safety "
                       f"{rob.unsafe_probability:.3f}")
    else:
        typer.echo(f"no plan ({result.status}): {result.message}")
    if not result.success:
        for name, path in (("--plot", plot), ("--animate", animate)):
            if path is not None:
                typer.echo(f"taut: {name}: {path} not written: there is no plan to draw",
                           err=True)


def _check_options(budget: float | None, sheet_margin: float, seed: int, iterations: int,
                   search: str, spacing: float, both_baselines: bool,
                   robustness: float | None, trials: int) -> None:
    """Every option's range, before any work (one line naming the option)."""
    if budget is not None and not 0 < budget <= MAX_BUDGET_S:
        raise InvalidInputError("--budget", f"must be in (0, {MAX_BUDGET_S:g}] s, got {budget:g}")
    if not 0 <= sheet_margin <= 1.0:
        raise InvalidInputError("--sheet-margin", f"must be in [0, 1] m, got {sheet_margin:g}")
    as_count(seed, "--seed", minimum=0)
    as_count(iterations, "--iterations", minimum=1, maximum=MAX_ITERATIONS)
    _check_search(search)
    if not 0.005 <= spacing <= 1.0:
        raise InvalidInputError("--spacing", f"must be in [0.005, 1] m, got {spacing:g}")
    if both_baselines:
        raise InvalidInputError("--baseline", "give at most one of --baseline and "
                                "--disc-baseline")
    if robustness is not None and not 0 <= robustness <= 1.0:
        raise InvalidInputError("--robustness", f"must be in [0, 1] m, got {robustness:g}")
    as_count(trials, "--trials", minimum=1, maximum=MAX_TRIALS)


def _check_search(search: str) -> None:
    """``--search`` names a known search whose library is installed."""
    from ..plan.se2._ompl import engine
    try:
        engine(search)
    except InvalidInputError as exc:
        raise InvalidInputError("--search", exc.problem) from None


def register(app: typer.Typer) -> None:
    """Add ``taut plan`` to the application."""
    app.command("plan")(plan_command)
