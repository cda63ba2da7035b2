"""`taut cdpr simulate`: a controller driving the cable robot along a pick-and-place or CSV
reference (FASTKIT paper §2.2), with seeded exit-point errors; prints the tracking error,
tension extremes, slack time and limit episodes; optional JSON, figure and 3D animation.

Exit codes: 0 every monitor clean; 1 the run violated a limit or the plant diverged (one
line on stderr says so); 2 bad input.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from ..errors import InvalidInputError
from .._validate import as_choice
from ._cdpr_common import given, load_robot
from ._paths import ANIMATION_SUFFIXES, FIGURE_SUFFIXES, JSON_SUFFIXES, output_path
from ._progress import working
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, write_recordings

__all__ = ["add_simulate"]

def _waypoints(text: str) -> np.ndarray:
    """``"x,y,z; x,y,z; ..."`` -> (W, 3)."""
    try:
        pts = [[float(v) for v in part.replace(" ", ",").split(",") if v != ""]
               for part in text.split(";") if part.strip()]
    except ValueError:
        raise InvalidInputError("--waypoints", "must be 'x,y,z; x,y,z; ...' in m") from None
    if len(pts) < 2 or any(len(p) != 3 for p in pts):
        raise InvalidInputError("--waypoints", "needs at least two 'x,y,z' points in m, "
                                               "separated by ';'")
    arr = np.array(pts)
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError("--waypoints", "contains NaN or infinite values")
    return arr


def add_simulate(sub: typer.Typer) -> None:
    """Add ``simulate`` to the ``cdpr`` sub-application (long because the command's
    options are declared in its signature, one typer option each)."""

    @sub.command("simulate", help="Simulate velocity or torque control of the cable robot "
                                  "(FASTKIT §2.2).")
    def simulate_cmd(
        model: str = typer.Argument(..., help="Preset name (fastkit, ipanema) or model file."),
        waypoints: Optional[str] = typer.Option(
            None, "--waypoints", help="Pick-and-place waypoints 'x,y,z; x,y,z; ...' (m)."),
        reference: Optional[Path] = typer.Option(
            None, "--reference", help="CSV reference: time,x,y,z,roll,pitch,yaw (s, m, rad)."),
        controller: str = typer.Option("torque", "--controller", help="velocity, torque or "
                                       "computed_torque (taut.cdpr.CONTROLLERS); gains for "
                                       "the control rate and latency by "
                                       "taut.cdpr.tune_for_rate."),
        exit_error: Optional[float] = typer.Option(
            None, "--exit-error", help="Std. dev. of seeded exit-point errors, m (default: "
                                       "the library's, none; taut.cdpr.ModelErrors)."),
        seed: Optional[int] = typer.Option(None, "--seed", help="Seed of the model errors "
                                           "(default: the library's)."),
        speed: Optional[float] = typer.Option(
            None, "--speed", help="Pick-and-place peak speed, m/s (default: the library's, "
                                  "taut.cdpr.pick_and_place)."),
        profile: Optional[str] = typer.Option(
            None, "--profile", help="Velocity profile of each segment: quintic or "
                                    "trapezoidal (default: the library's)."),
        dwell: Optional[float] = typer.Option(
            None, "--dwell", help="Rest at each waypoint, s (default: the library's)."),
        control_rate: Optional[float] = typer.Option(
            None, "--control-rate", help="Controller rate, Hz (default: the library's, "
                                         "taut.cdpr.simulate)."),
        tension_gain: Optional[float] = typer.Option(
            None, "--tension-gain", help="Velocity control with tension feedback, 1/s "
                                         "(default: the library's, 0 = pure velocity "
                                         "control; the tension is estimated from the drive "
                                         "torques)."),
        latency: Optional[float] = typer.Option(
            None, "--latency", help="Delay from measurement to actuation, s (default: the "
                                    "library's, taut.cdpr.Sensing)."),
        ideal_pose: bool = typer.Option(False, "--ideal-pose", help="Give the controller "
                                        "the true platform pose (default: estimated from "
                                        "the encoders, as on FASTKIT)."),
        stabilisers: bool = typer.Option(False, "--stabilisers",
                                         help="Deploy the stabilisers of mobile bases."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON "
                                     "(the result's fields under the same names)."),
        json_out: Optional[Path] = typer.Option(None, "--out", help="Write the JSON result "
                                                "to this file (.json)."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Figure (PNG/PDF)."),
        animate: Optional[Path] = typer.Option(None, "--animate", help="3D animation (GIF)."),
        mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP + " Bases as "
                                            "robot_<i>, the platform as the object."),
        rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
    ) -> None:
        """``taut cdpr simulate`` (help text above); long because its options, one typer
        declaration each, are in the signature."""
        if (waypoints is None) == (reference is None):
            raise InvalidInputError("--waypoints", "give exactly one of --waypoints and "
                                                   "--reference")
        if exit_error is not None and not (np.isfinite(exit_error) and 0 <= exit_error <= 1):
            raise InvalidInputError("--exit-error", "must be a number of m in [0, 1]")
        if latency is not None and not (np.isfinite(latency) and 0 <= latency <= 1):
            raise InvalidInputError("--latency", "must be a number of s in [0, 1]")
        output_path(json_out, "--out", JSON_SUFFIXES)
        output_path(plot, "--plot", FIGURE_SUFFIXES)
        output_path(animate, "--animate", ANIMATION_SUFFIXES)
        mcap, rerun = recording_paths(mcap, rerun)
        from ..cdpr import CONTROLLERS, ModelErrors, pick_and_place
        as_choice(controller, CONTROLLERS, "--controller")
        from ..io.cdpr_dynamics import load_cdpr_dynamics
        from ..io.cdpr_reference import read_reference_csv
        from ..io.files import write_json
        from ..io.serialize import to_json
        from ..io.serialize import control_result_to_dict

        robot = load_robot(model, stabilisers)
        dyn = load_cdpr_dynamics(model)
        if waypoints is not None:
            ref = pick_and_place(robot, _waypoints(waypoints),
                                 **given(speed=speed, profile=profile, dwell=dwell))
        else:
            ref = read_reference_csv(robot, reference)  # type: ignore[arg-type]
        errs = ModelErrors(**given(exit_offset=exit_error, seed=seed))
        if tension_gain is not None and controller != "velocity":
            raise InvalidInputError("--tension-gain", "applies to --controller velocity")
        from ..cdpr import Sensing, tune_for_rate
        sens = Sensing(ideal_pose=ideal_pose,
                       **given(latency=latency))
        ctl, sens = tune_for_rate(CONTROLLERS[controller](**given(tension_gain=tension_gain)),
                                  sens, **given(control_rate=control_rate), dynamics=dyn)
        run = _run(robot, ref, ctl, errs, control_rate, dyn, sens)
        if json_out is not None:
            write_json(control_result_to_dict(run), json_out)
        if as_json:
            typer.echo(to_json(control_result_to_dict(run)))
        if plot is not None:
            from ..viz.cdpr_sim import plot_control
            plot_control(run, plot)
        if animate is not None:
            from ..viz.cdpr_sim import animate_control
            animate_control(robot, run, animate)
        write_recordings(run, mcap, rerun, quiet=True, robot=robot)
        if not as_json:
            _report(run, json_out, plot, animate, mcap, rerun)
        if not run.success:
            print(f"taut: {run.status}: {run.message}", file=sys.stderr)
            raise typer.Exit(1)


def _run(robot, ref, ctl, errs, rate, dyn, sensing):
    """simulate() with progress on stderr (a bar on a terminal, else a line every 10 s)."""
    from ..cdpr import simulate

    with working(f"cdpr simulate ({ctl.name} control)") as update:
        return simulate(robot, ref, ctl, model_errors=errs, dynamics=dyn, progress=update,
                        sensing=sensing,
                        **given(control_rate=rate))


def _report(run, json_out, plot, animate, mcap=None, rerun=None) -> None:
    typer.echo(f"{run.controller['name']} control over {run.times[-1]:.2f} s: {run.status}")
    typer.echo(f"  tracking error: max {1e3 * run.tracking_error.max():.3f} mm, rms "
               f"{1e3 * np.sqrt(np.mean(run.tracking_error ** 2)):.3f} mm")
    typer.echo(f"  tensions: {run.tensions.min():.2f} .. {run.tensions.max():.2f} N "
               f"(limits {run.t_min.min():g} .. {run.t_max.max():g} N)")
    typer.echo(f"  slack time {run.slack_time:.3f} s, worst over-tension "
               f"{max(run.worst_over_tension, 0.0):.2f} N")
    if run.tipping_margin.shape[1]:
        typer.echo(f"  minimum tipping margin {run.tipping_margin.min():.2f} N m")
    for e in run.events[:10]:
        typer.echo(f"  event: {e.describe()}")
    if len(run.events) > 10:
        typer.echo(f"  ... {len(run.events) - 10} more events")
    for label, p in (("result", json_out), ("figure", plot), ("animation", animate),
                     ("ROS 2 recording", mcap), ("Rerun recording", rerun)):
        if p is not None:
            typer.echo(f"{label} written to {p}")
