"""`taut physics`: check every rest state taut reports for a scenario in MuJoCo."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer

from ..errors import InvalidInputError, ScenarioError
from ..io.sheet_scenario import load_sheet_scenario


def _output(path: Optional[Path], option: str, suffixes: tuple[str, ...]) -> None:
    """Reject an output path before any work: wrong suffix or missing folder."""
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        raise InvalidInputError(option, f"must end in {' or '.join(suffixes)}, got {path.name!r}")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise InvalidInputError(option, f"folder {str(parent)!r} does not exist")


def check_to_dict(check: Any) -> dict[str, Any]:
    """JSON-ready form of an :class:`~taut.physics.EquilibriaCheck` (0-based taut sets,
    scenario units)."""
    def f(a: np.ndarray) -> list[float]:
        return [float(x) for x in np.asarray(a).ravel()]

    return {
        "success": bool(check.success), "status": check.status, "message": check.message,
        "mesh": check.mesh, "ball_radius": check.ball, "hold_tolerance": check.hold_tolerance,
        "states": [{"taut": list(s.taut), "status": s.status, "held": s.held,
                    "agrees": s.agrees, "predicted": f(s.predicted), "tied": f(s.tied),
                    "settled": f(s.settled), "difference": f(s.difference),
                    "tied_difference": f(s.tied_difference), "sliding": float(s.sliding),
                    "moved": float(s.moved), "time_s": float(s.time)}
                   for s in check.states],
    }


def format_check(check: Any, *, name: str | None, units: str | None) -> str:
    """Plain-text table, robots numbered 1..N as in the papers."""
    u = f" [{units}]" if units else ""
    head = ("taut", "taut says", "physics", "pull/mg", f"tied dx, dy, dz{u}",
            f"released dx, dy, dz{u}", "agrees", "s")
    rows = [head]
    for s in check.states:
        rows.append(("{" + ",".join(str(i + 1) for i in s.taut) + "}",
                     s.status.replace("_", " "), "held" if s.held else "not held",
                     f"{s.sliding:.3f}", ", ".join(f"{v:+.1f}" for v in s.tied_difference),
                     ", ".join(f"{v:+.1f}" for v in s.difference),
                     "yes" if s.agrees else "NO", f"{s.time:.1f}"))
    widths = [max(len(r[c]) for r in rows) for c in range(len(head))]
    lines = [name] if name else []
    lines.append(f"MuJoCo check, mesh {check.mesh}, ball radius {check.ball:.3g}{u}: "
                 f"{check.message}")
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(lines)


def register(app: typer.Typer) -> None:
    """Add ``taut physics``."""

    @app.command("physics")
    def physics_command(
        scenario: Path = typer.Argument(..., help="Sheet scenario file (YAML or JSON) with "
                                        "hold_height, sheet and formation."),
        as_json: bool = typer.Option(False, "--json", help="Print JSON instead of a table."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write a figure of the "
                                            "settled sheet of every state (.png)."),
        video: Optional[Path] = typer.Option(None, "--video", help="Write an animation of "
                                             "a ball dropped over the robots (.gif)."),
        mesh: Optional[int] = typer.Option(None, "--mesh", help="Mesh spacings across the "
                                           "sheet's widest vertex pair (default 10)."),
    ) -> None:
        """Check taut's rest states in MuJoCo: tie the object at each state's contact
        point, settle, release; exit 1 when physics disagrees with taut."""
        _output(plot, "--plot", (".png",))
        _output(video, "--video", (".gif",))
        sc = load_sheet_scenario(scenario)
        if sc.formation is None:
            raise ScenarioError("formation", "required key is missing (taut physics needs "
                                "the robots' positions)")
        try:
            from ..physics import DEFAULT_MESH, check_equilibria, settle
            import mujoco  # noqa: F401
        except ImportError:
            raise InvalidInputError("physics", "needs MuJoCo: pip install 'taut[physics]'"
                                    ) from None
        div = DEFAULT_MESH if mesh is None else mesh
        if not as_json and sys.stdout.isatty():
            from rich.progress import Progress
            with Progress(transient=True) as bar:
                task = bar.add_task("settling each state", total=None)
                check = check_equilibria(sc.sheet, sc.formation, sc.hold_height, mesh=div,
                                         progress=lambda d, t: bar.update(task, completed=d,
                                                                          total=t))
        else:
            check = check_equilibria(sc.sheet, sc.formation, sc.hold_height, mesh=div)
        if as_json:
            typer.echo(json.dumps(check_to_dict(check), indent=2))
        else:
            typer.echo(format_check(check, name=sc.name, units=sc.units))
        if plot is not None:
            import matplotlib.pyplot as plt
            from ..viz.physics import plot_equilibria_check
            plt.close(plot_equilibria_check(check, sc.formation, sc.hold_height, plot,
                                            units=sc.units, title=sc.name))
            if not as_json:
                typer.echo(f"figure written to {plot}")
        if video is not None:
            from ..viz.physics import animate_settle
            drop = settle(sc.sheet, sc.formation, sc.hold_height, trace=True, mesh=div)
            animate_settle(drop, sc.formation, sc.hold_height, video)
            if not as_json:
                typer.echo(f"animation written to {video}")
        if not check.success:
            raise typer.Exit(1)
