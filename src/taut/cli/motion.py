"""`taut ik` (where must the robots stand?) and `taut simulate` (what does the object do
while they move?)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional, Tuple

import numpy as np
import typer

from .._validate import MAX_SHEET_LENGTH, as_mass, check_range
from ..errors import InvalidInputError
from ..io.serialize import ik_to_dict, simulation_to_dict, to_json
from ._paths import FIGURE_SUFFIXES, output_path
from ._progress import working
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, sheet_unit, write_recordings

if TYPE_CHECKING:
    from ..sheet.ik.inverse import IKResult
    from ..sheet.sim.simulate import SimulationResult


def _ik_table(r: "IKResult", units: str | None) -> str:
    u = f" {units}" if units else ""
    p = r.object
    lines = [f"object at ({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}){u}, contact "
             f"({r.contact[0]:.4g}, {r.contact[1]:.4g}); all {len(r.weights)} cables taut, "
             f"stable ({r.construction})",
             f"{'robot':>5}  {'x':>10}  {'y':>10}  {'angle[deg]':>10}  {'weight':>7}"
             + ("  tension[N]" if r.tensions is not None else "")]
    for i, (xy, th, w) in enumerate(zip(r.formation, r.angles, r.weights), 1):
        row = f"{i:>5}  {xy[0]:>10.4f}  {xy[1]:>10.4f}  {np.degrees(th):>10.2f}  {w:>7.4f}"
        if r.tensions is not None:
            row += f"  {r.tensions[i - 1]:>10.4g}"
        lines.append(row)
    return "\n".join(lines)


def _sim_table(r: "SimulationResult", time: np.ndarray, units: str | None) -> str:
    u = f" {units}" if units else ""
    z = r.object[:, 2]
    lines = [f"{len(r)} steps, {len(r.events)} event(s), {len(r.jumps)} jump(s); object "
             f"height {np.nanmin(z):.4g}..{np.nanmax(z):.4g}{u}"]
    for e in r.events:
        k = min(e.step, len(time) - 1)
        tk = time[k - 1] + e.fraction * (time[k] - time[k - 1]) if k else time[0]
        before = "{" + ",".join(str(i + 1) for i in e.taut_before) + "}"
        after = "{" + ",".join(str(i + 1) for i in e.taut_after) + "}"
        extra = f", drop {e.drop:.4g}{u}" if e.kind == "jump" else ""
        lines.append(f"  step {e.step} (t = {tk:.4g}): {e.kind.replace('_', ' ')} "
                     f"{before} -> {after}{extra}")
    last = r.object[-1]
    lines.append(f"final object position ({last[0]:.4g}, {last[1]:.4g}, {last[2]:.4g}){u}")
    return "\n".join(lines)


def register(app: typer.Typer) -> None:
    """Add ``taut ik`` and ``taut simulate``."""

    @app.command("ik")
    def ik_command(
        scenario: Path = typer.Argument(..., help="Scenario file (YAML or JSON) with "
                                        "hold_height and sheet (a formation, if present, is "
                                        "validated but not used)."),
        object_position: Tuple[float, float, float] = typer.Option(
            ..., "--object", help="Target object position X Y Z (sheet units: the "
            "scenario's units)."),
        contact: Optional[Tuple[float, float]] = typer.Option(
            None, "--contact", help="Contact point U V on the sheet (sheet frame, sheet "
            "units); default the sheet's area centroid."),
        heading: float = typer.Option(0.0, "--heading", help="Formation heading, rad "
                                      "(counter-clockwise turn about the vertical)."),
        mass: Optional[float] = typer.Option(None, "--mass", help="Object mass in kg "
                                             "(overrides the scenario's); gives tensions."),
        as_json: bool = typer.Option(False, "--json", help="Print JSON instead of a table."),
    ) -> None:
        """Inverse kinematics: where the robots must stand so that the object rests
        stably at the target with every cable taut."""
        from dataclasses import replace

        from ..io.sheet_scenario import load_sheet_scenario
        from ..sheet.ik.inverse import inverse_kinematics

        check_range(object_position, "--object", MAX_SHEET_LENGTH, "sheet units")
        if contact is not None:
            check_range(contact, "--contact", MAX_SHEET_LENGTH, "sheet units")
        check_range(heading, "--heading", 1e4, "rad")
        m = as_mass(mass, "--mass") if mass is not None else None
        sc = load_sheet_scenario(scenario)
        team = sc.team if m is None else replace(sc.team, mass=m)
        with working("ik"):
            r = inverse_kinematics(team, object_position, contact=contact, heading=heading)
        if not r.success:                      # a valid question answered "no": exit 1
            typer.echo(f"taut: {r.status}: {r.message}", err=True)
            raise typer.Exit(1)
        if as_json:
            typer.echo(to_json(ik_to_dict(r, sc.units)))
        else:
            typer.echo(_ik_table(r, sc.units))

    @app.command("simulate")
    def simulate_command(
        scenario: Path = typer.Argument(..., help="Scenario file with hold_height and sheet."),
        trajectory: Path = typer.Option(..., "--trajectory", help="CSV: time, then x, y of "
                                        "each robot, one row per step."),
        mass: Optional[float] = typer.Option(None, "--mass", help="Object mass in kg "
                                             "(overrides the scenario's); gives tensions."),
        as_json: bool = typer.Option(False, "--json", help="Print JSON instead of a summary."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write a figure (object "
                                            "height with events; top view of all paths)."),
        mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP),
        rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
    ) -> None:
        """Quasi-static simulation of the object while the robots follow a trajectory."""
        from dataclasses import replace

        from ..io.sheet_scenario import load_sheet_scenario
        from ..io.trajectory import load_trajectory
        from ..sheet.sim.simulate import simulate

        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        mcap, rerun = recording_paths(mcap, rerun)
        m = as_mass(mass, "--mass") if mass is not None else None
        sc = load_sheet_scenario(scenario)
        unit = sheet_unit(sc.units, mcap, rerun)
        team = sc.team if m is None else replace(sc.team, mass=m)
        traj = load_trajectory(trajectory)
        if traj.n_robots != team.n:
            raise InvalidInputError(str(trajectory), f"has {traj.n_robots} robots but the "
                                    f"sheet has {team.n} vertices")
        with working("simulate"):
            r = simulate(team, traj.formations)
        if as_json:
            typer.echo(to_json(simulation_to_dict(r, traj.time, sc.units), indent=None))
        else:
            typer.echo(_sim_table(r, traj.time, sc.units))
        if plot is not None:
            from ..viz.motion import plot_simulation

            plot_simulation(r, plot, time=traj.time, units=sc.units, title=sc.name)
            if not as_json:
                typer.echo(f"figure written to {plot}")
        write_recordings(r, mcap, rerun, quiet=as_json, length_unit=unit, times=traj.time)
