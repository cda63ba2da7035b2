"""`taut plan`: transport plan with obstacle crossing for a sheet-carrying team."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer

from ..errors import InvalidInputError
from ..io.plan_scenario import load_plan_scenario
from ..plan.planner import plan
from ..plan.result import PlanResult

__all__ = ["register", "plan_to_dict", "plan_command"]


def plan_to_dict(r: PlanResult) -> dict[str, Any]:
    """JSON form of a plan: ``success``, ``status``, ``message``, ``reason`` (deprecated:
    ``message`` on failure, null on success), ``times`` [T], ``robots`` [T][N][2],
    ``object`` [T][3], ``taut`` [T][k] (0-based), ``crossed``, ``bypassed``, plus
    ``path_length`` (m) and ``duration`` (s) (null on failure) and ``planner``."""
    def num(x: float) -> float | None:
        return float(x) if np.isfinite(x) else None

    return {
        "success": bool(r.success),
        "status": r.status,
        "message": r.message,
        "reason": None if r.success else r.message,
        "planner": r.planner,
        "times": [float(t) for t in r.times],
        "robots": np.asarray(r.robots, dtype=float).tolist(),
        "object": np.asarray(r.object, dtype=float).tolist(),
        "taut": [list(s) for s in r.taut],
        "crossed": list(r.crossed),
        "bypassed": list(r.bypassed),
        "path_length": num(r.path_length),
        "duration": num(r.duration),
    }


def plan_command(
    scenario: Path = typer.Argument(..., help="Planning scenario file (YAML or JSON)."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the plan as JSON."),
    animate: Optional[Path] = typer.Option(None, "--animate", help="Write an animated GIF."),
    baseline: bool = typer.Option(False, "--baseline",
                                  help="Bypass-only SE(2) baseline (no crossing)."),
    disc_baseline: bool = typer.Option(False, "--disc-baseline",
                                       help="Bypass-only disc-model baseline."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write the summary figure."),
    algorithm2: bool = typer.Option(False, "--algorithm2",
                                    help="Cross only as the paper's Algorithm 2 does (the "
                                         "obstacle passes under the object)."),
    budget: float = typer.Option(10.0, "--budget", help="Time budget of the search, s."),
    sheet_margin: float = typer.Option(0.01, "--sheet-margin",
                                       help="Robot pairs stay this far inside their sheet "
                                            "distance, m."),
    seed: int = typer.Option(0, "--seed", help="Seed of the SE(2) search."),
) -> int:
    """Plan the transport of the object from start to goal, crossing low obstacles under
    the sheet where that is faster; exit 0 with a plan, 1 when no plan exists."""
    for flag, out in (("--json", json_out), ("--plot", plot), ("--animate", animate)):
        if out is not None and (out.is_dir() or not out.parent.is_dir()):
            raise InvalidInputError(flag, f"cannot write {str(out)!r} (not a file in an "
                                          "existing directory)")
    sc = load_plan_scenario(scenario)
    print(f"taut plan: planning {sc.name or scenario.name} (budget {budget:g} s)...",
          file=sys.stderr)
    result = plan(sc, baseline="disc" if disc_baseline else baseline,
                  method="algorithm2" if algorithm2 else "se2", time_budget=budget,
                  sheet_margin=sheet_margin, seed=seed)
    if json_out is not None:
        json_out.write_text(json.dumps(plan_to_dict(result)) + "\n", encoding="utf-8")
    if result.success and (plot is not None or animate is not None):
        from ..viz.plan import animate_plan, plot_plan
        if plot is not None:
            plot_plan(sc, result, plot)
        if animate is not None:
            animate_plan(sc, result, animate)
    if result.success:
        typer.echo(f"plan: {len(result.times)} samples, {result.duration:.2f} s, path "
                   f"{result.path_length:.3f} m, crossed [{', '.join(result.crossed)}], "
                   f"object at {result.object[:, 2].max():.3f} m")
        return 0
    typer.echo(f"no plan ({result.status}): {result.message}")
    return 1


def register(app: typer.Typer) -> None:
    """Add ``taut plan`` to the application."""
    app.command("plan")(plan_command)
