"""`taut physics`: check every rest state taut reports for a scenario in MuJoCo."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

from ..errors import ScenarioError
from ._paths import ANIMATION_SUFFIXES, output_path
from ._progress import working
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, sheet_unit, write_recordings


def format_check(check: Any, *, name: str | None, units: str | None) -> str:
    """Plain-text table, robots numbered 1..N as in the papers."""
    u = f" [{units}]" if units else ""
    head = ("taut", "taut says", "physics", "pull/mg", "taut pull/mg", f"tied dx, dy, dz{u}",
            f"released dx, dy, dz{u}", "agrees", "s")
    rows = [head]
    for s in check.states:
        released = (", ".join(f"{v:+.1f}" for v in s.difference)
                    if s.success or s.status == "not_strict"
                    else f"FAILED ({s.status.replace('_', ' ')})")
        if s.reached is not None:
            released += " -> {" + ",".join(str(i + 1) for i in s.reached) + "}"
        if s.status == "not_strict":
            released += " MARGINAL"
        held = "held" if s.held else "not held"
        rows.append(("{" + ",".join(str(i + 1) for i in s.taut) + "}",
                     s.kind.replace("_", " "), held if s.resolved else f"{held} (unresolved)",
                     f"{s.sliding:.2g}", f"{s.predicted_sliding:.2g}",
                     ", ".join(f"{v:+.1f}" for v in s.tied_difference),
                     released, "yes" if s.agrees else "NO", f"{s.time:.1f}"))
    widths = [max(len(r[c]) for r in rows) for c in range(len(head))]
    lines = [name] if name else []
    lines.append(f"MuJoCo check, mesh {check.mesh}, ball radius {check.ball:.3g}{u}: "
                 f"{check.message}")
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    lines += [f"{'marginal' if s.status == 'not_strict' else 'failed'}: {s.message}"
              for s in check.states if not s.success]
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
        mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP + " One checked "
                                            "state a second, on its settled sheet."),
        rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
    ) -> None:
        """Check taut's rest states in MuJoCo: tie the object at each state's contact
        point, settle, release; exit 1 when physics disagrees with taut, a simulation
        failed (the object left the sheet, diverged or did not settle) or a released
        object left a marginal stable state. The ball has the scenario's object.radius
        and mass when given."""
        from ..io.serialize import equilibria_check_to_dict, to_json
        from ..io.sheet_scenario import load_sheet_scenario

        output_path(plot, "--plot", (".png",))
        output_path(video, "--video", ANIMATION_SUFFIXES)
        sc = load_sheet_scenario(scenario)
        if sc.formation is None:
            raise ScenarioError("formation", "required key is missing (taut physics needs "
                                "the robots' positions)")
        mcap, rerun = recording_paths(mcap, rerun)
        unit = sheet_unit(sc.units, mcap, rerun)
        from ..physics import DEFAULT_MESH, replay_equilibria, settle
        div = DEFAULT_MESH if mesh is None else mesh
        with working("physics (settling each state)") as update:
            check = replay_equilibria(sc.team, sc.formation, mesh=div, ball=sc.object_radius,
                                      progress=update)
        if as_json:
            typer.echo(to_json(equilibria_check_to_dict(check, sc.units)))
        else:
            typer.echo(format_check(check, name=sc.name, units=sc.units))
        if plot is not None:
            import matplotlib.pyplot as plt
            from ..viz.physics import plot_equilibria_check
            plt.close(plot_equilibria_check(check, sc.formation, sc.team.hold_height, plot,
                                            units=sc.units, title=sc.name))
            if not as_json:
                typer.echo(f"figure written to {plot}")
        if video is not None:
            from ..viz.physics import animate_settle
            drop = settle(sc.team, sc.formation, trace=True, mesh=div, ball=sc.object_radius)
            animate_settle(drop, sc.formation, sc.team.hold_height, video, units=sc.units)
            if not as_json:
                typer.echo(f"animation written to {video}")
        write_recordings(check, mcap, rerun, quiet=as_json, length_unit=unit, team=sc.team,
                         formation=sc.formation)
        if not check.success:
            raise typer.Exit(1)
