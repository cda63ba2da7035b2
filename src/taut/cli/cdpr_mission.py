"""`taut cdpr mission FILE`: the warehouse's kitting mission planned and simulated (issue
30): deployment sites, routes, time-optimal pick/carry/place motions run in the control
simulation, and the fixed 1 m/s baseline. Prints one line per phase and the totals;
optional JSON, figure and animation.

Exit codes: 0 every served task done with every monitor clean (unserved tasks are listed,
not failures); 1 a site could not be reached or a phase broke a limit (one line on stderr);
2 bad input.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Optional

import typer

from ._paths import ANIMATION_SUFFIXES, FIGURE_SUFFIXES, output_path
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, write_recordings
from ._progress import working

__all__ = ["add_mission"]


def _margin(v: float, digits: int = 1) -> str:
    return "-" if v != v else ("inf" if v == float("inf") else f"{v:.{digits}f}")


def _report(res: Any) -> None:
    """The phase table and the totals of a :class:`taut.cdpr.MissionResult`."""
    typer.echo(f"{'phase':>8}  {'task':>6}  {'site':>4}  {'start [s]':>9}  {'end [s]':>8}  "
               f"{'tension margin [N]':>18}  {'tipping margin [N m]':>20}  "
               f"{'cables-shelves [m]':>18}  {'bases-shelves [m]':>17}")
    for p in res.phases:
        typer.echo(f"{p.kind:>8}  {p.task or '-':>6}  {p.site + 1:>4}  {p.start:9.2f}  "
                   f"{p.end:8.2f}  {_margin(p.min_tension_margin):>18}  "
                   f"{_margin(p.min_tipping_margin):>20}  "
                   f"{_margin(p.min_cable_clearance, 3):>18}  "
                   f"{_margin(p.min_footprint_clearance, 3):>17}"
                   + ("" if p.success else "  !"))
    for r in res.repositions:
        typer.echo(f"active base before {r.task}: offset {r.offset:+.2f} m, best saving "
                   f"{r.best_saving:.3f} s, move {r.move_time:.2f} s")
    typer.echo(f"total time: {res.total_time:.2f} s   baseline (1 m/s profile): "
               f"{res.baseline_total_time:.2f} s   ratio {1 / res.speedup:.3f}")
    typer.echo(f"platform motions: {res.motion_time:.2f} s   baseline: "
               f"{res.baseline_motion_time:.2f} s")
    for u in res.unserved:
        typer.echo(f"unserved: {u.name}: {u.reason}")
    typer.echo(res.message)


def _offsets(text: Optional[str]) -> list[float]:
    """The ``--active-base-offsets`` list, m."""
    if not text:
        return []
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        from ..errors import InvalidInputError
        raise InvalidInputError("--active-base-offsets",
                                f"must be comma-separated numbers (m), got {text!r}") from None


def add_mission(sub: typer.Typer) -> None:
    """Add ``mission`` to the ``cdpr`` sub-application."""

    @sub.command("mission", help="Plan and simulate a warehouse kitting mission (navigate, "
                                 "deploy, pick, carry, place, retract).")
    def mission_cmd(
        warehouse: Path = typer.Argument(..., help="Warehouse file (YAML/JSON)."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Figure (PNG/PDF/SVG): "
                                            "floor plan, timeline, margins."),
        animate: Optional[Path] = typer.Option(None, "--animate", help="Animation (GIF)."),
        mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP + " The "
                                            "platform and the coupled bases' track."),
        rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
        offsets: Optional[str] = typer.Option(
            None, "--active-base-offsets", help="Comma-separated offsets (m) the active "
            "base may move to along the shelf face between tasks, e.g. '-0.6,-0.3,0.3,0.6' "
            "(taken only when the motion time saved beats the move's cost)."),
    ) -> None:
        """Exit 0 when every served task is done with every monitor clean."""
        output_path(plot, "--plot", FIGURE_SUFFIXES)
        output_path(animate, "--animate", ANIMATION_SUFFIXES)
        mcap, rerun = recording_paths(mcap, rerun)
        from ..cdpr import plan_mission
        from ..io import load_warehouse
        from ..io.serialize import mission_to_dict, to_json

        wh = load_warehouse(warehouse)
        moves = _offsets(offsets)
        from ..errors import InvalidInputError
        try:
            with working(f"cdpr mission ({len(wh.tasks)} tasks)") as update:
                res = plan_mission(wh, progress=update, active_base_offsets=moves)
        except InvalidInputError as exc:       # the library's range check, named as the option
            if exc.field != "active_base_offsets":
                raise
            raise InvalidInputError("--active-base-offsets", exc.problem) from None
        if as_json:
            typer.echo(to_json(mission_to_dict(res)))
        else:
            _report(res)
        if plot is not None:
            from ..viz.cdpr_mission import plot_mission
            plot_mission(wh, res, plot)
        if animate is not None:
            from ..viz.cdpr_mission import animate_mission
            animate_mission(wh, res, animate)
        if len(res.track_times):
            write_recordings(res, mcap, rerun, quiet=as_json)
        if not res.success:
            print(f"taut: {res.status}: {res.message}", file=sys.stderr)
            raise typer.Exit(1)
