"""`taut fk`: every rest state of the object for the formation in a scenario file."""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

import typer

from .._validate import as_mass
from ..errors import ScenarioError
from ..io.serialize import fk_result_to_dict, to_json
from ._paths import FIGURE_SUFFIXES, output_path
from ._progress import working
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, sheet_unit, write_recordings

if TYPE_CHECKING:
    from ..sheet.fk.results import FKResult


class FKMethod(str, Enum):
    fast = "fast"
    exhaustive = "exhaustive"
    subsets = "subsets"


def _fmt(values: Any, digits: int = 4) -> str:
    return ", ".join(f"{v:.{digits}g}" for v in values)


def format_table(result: FKResult, *, name: str | None, units: str | None) -> str:
    """Plain-text report, robots numbered 1..N as in the papers."""
    u = f" {units}" if units else ""
    lines = []
    if name:
        lines.append(name)
    lines.append(f"N = {result.sheet.n} robots, hold height {result.hold_height:g}{u}, "
                 f"method {result.method}: {len(result.equilibria)} solution(s), "
                 f"{len(result.stable)} stable")
    rows = [("#", "taut", f"x_o", "y_o", "z_o", "contact (u, v)", "kind", "weights",
             "tensions [N]")]
    for k, e in enumerate(result.equilibria, 1):
        rows.append((str(k), "{" + ",".join(str(i + 1) for i in e.taut) + "}",
                     f"{e.object[0]:.2f}", f"{e.object[1]:.2f}", f"{e.object[2]:.2f}",
                     f"({e.contact[0]:.2f}, {e.contact[1]:.2f})", e.kind,
                     _fmt(e.weights, 3), "-" if e.tensions is None else _fmt(e.tensions, 4)))
    if len(rows) == 1:
        rows = []
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))] if rows else []
    right = {0, 2, 3, 4}
    for r in rows:
        lines.append("  ".join(cell.rjust(w) if c in right else cell.ljust(w)
                               for c, (cell, w) in enumerate(zip(r, widths))).rstrip())
    if not result.equilibria:
        lines.append(result.message)            # why: worked out by the library
    f = result.funnel
    if f is not None:
        lines.append(f"Algorithm 1 funnel: {f.combinations} taut sets tried, {f.form_closure} "
                     f"form closure, {f.cqp_feasible} CQP feasible, {f.height_feasible} "
                     f"height feasible, {f.force_closure} force closure")
    return "\n".join(lines)


def register(app: typer.Typer) -> None:
    """Add ``taut fk``."""

    @app.command("fk")
    def fk_command(
        scenario: Path = typer.Argument(..., help="Scenario file (YAML or JSON) with "
                                        "hold_height, sheet, formation, optional mass/units/name."),
        as_json: bool = typer.Option(False, "--json", help="Print machine-readable JSON "
                                     "(0-based taut indices) instead of a table."),
        method: FKMethod = typer.Option(FKMethod.fast, "--method", help="fast: convex-hull "
                                        "enumeration; exhaustive: the paper's Algorithm 1 "
                                        "with its step counts; subsets: all sets of <= 5 cables."),
        mass: Optional[float] = typer.Option(None, "--mass", help="Object mass in kg "
                                             "(overrides the scenario's); gives tensions in N."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write a 3D figure of every "
                                            "equilibrium to this file (.png, .pdf, .svg)."),
        mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP + " Records the "
                                            "lowest rest state."),
        rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
    ) -> int:
        """Forward kinematics: every place the object can rest, which are stable, and
        each robot's cable tension. Exit 0 with at least one equilibrium, 1 when there is
        none (the reason is printed), 2 on bad input."""
        from dataclasses import replace

        from ..io.sheet_scenario import load_sheet_scenario
        from ..sheet import forward_kinematics

        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        mcap, rerun = recording_paths(mcap, rerun)
        m = as_mass(mass, "--mass") if mass is not None else None
        sc = load_sheet_scenario(scenario)
        if sc.formation is None:
            raise ScenarioError("formation", "required key is missing (taut fk needs the "
                                "robots' positions)")
        unit = sheet_unit(sc.units, mcap, rerun)
        team = sc.team if m is None else replace(sc.team, mass=m)
        with working(f"fk ({method.value})"):
            result = forward_kinematics(team, sc.formation, method=method.value)
        if as_json:
            doc = fk_result_to_dict(result, sc.units)
            if not result.equilibria:
                doc["message"] = result.message
            typer.echo(to_json(doc))
        else:
            typer.echo(format_table(result, name=sc.name, units=sc.units))
        if plot is not None:
            from ..viz.sheet import plot_fk

            panels = 12
            plot_fk(result, plot, units=sc.units, title=sc.name, max_panels=panels)
            n = len(result.equilibria)
            note = f" ({panels} of {n} equilibria drawn, stable first)" if n > panels else ""
            if not as_json:
                typer.echo(f"figure written to {plot}{note}")
        write_recordings(result, mcap, rerun, quiet=as_json, length_unit=unit)
        return 0 if result.equilibria else 1
