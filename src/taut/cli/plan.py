"""`taut plan`: transport plan with obstacle crossing for a sheet-carrying team."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import typer

from ..errors import InvalidInputError
from ..io.serialize import plan_to_dict, robustness_to_dict, to_json
from ._paths import ANIMATION_SUFFIXES, FIGURE_SUFFIXES, JSON_SUFFIXES, output_path
from ._progress import working
from ._recordings import MCAP_HELP, RERUN_HELP, recording_paths, write_recordings

__all__ = ["register", "plan_command"]

#: The command-line option of each library keyword whose name differs (the others are
#: ``--`` and the keyword with dashes).
_OPTION_OF = {"time_budget": "--budget", "sigma": "--robustness"}


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
    mcap: Optional[Path] = typer.Option(None, "--mcap", help=MCAP_HELP + " With "
                                        "--trajectories: the per-robot trajectories."),
    rerun: Optional[Path] = typer.Option(None, "--rerun", help=RERUN_HELP),
    trajectories: Optional[Path] = typer.Option(
        None, "--trajectories", help="Also write one trajectory per robot (time s, x m, y "
        "m, heading rad; the object m), re-verified on the executed motion (.csv or "
        ".json); needs --max-speed, --max-accel and --max-yaw-rate."),
    drive: str = typer.Option("holonomic", "--drive", help="Robot drive of --trajectories: "
                              "holonomic or differential (faces its motion, turns in "
                              "place)."),
    max_speed: Optional[float] = typer.Option(None, "--max-speed", help="Largest robot "
                                              "speed of --trajectories, m/s."),
    max_accel: Optional[float] = typer.Option(None, "--max-accel", help="Largest "
                                              "robot acceleration of --trajectories, "
                                              "m/s^2."),
    max_yaw_rate: Optional[float] = typer.Option(None, "--max-yaw-rate",
                                                 help="Largest robot turn rate of "
                                                      "--trajectories, rad/s."),
    max_yaw_accel: Optional[float] = typer.Option(None, "--max-yaw-accel",
                                                  help="Largest robot yaw acceleration of "
                                                       "--trajectories, rad/s^2 (default: "
                                                       "as in taut.plan.robot_trajectories)."),
    reform_speed: Optional[float] = typer.Option(None, "--reform-speed",
                                                 help="Largest robot speed during "
                                                      "formation changes, m/s (default: "
                                                      "as in taut.plan.robot_trajectories, "
                                                      "quasi-static)."),
) -> int:
    """Plan the transport of the object from start to goal, crossing low obstacles under
    the sheet where that is faster; exit 0 with a plan, 1 when no plan exists, 2 on bad
    input. (Long because typer declares every option as a parameter; the body validates,
    calls the library and hands the outputs to the helpers below.)"""
    from ..io.plan_scenario import load_plan_scenario
    from ..plan._options import plan_options, robustness_options
    from ..plan.planner import run_plan

    out = output_path(out, "--out", JSON_SUFFIXES)
    plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
    animate = output_path(animate, "--animate", ANIMATION_SUFFIXES)
    mcap, rerun = recording_paths(mcap, rerun)
    if baseline and disc_baseline:
        raise InvalidInputError("--baseline", "give at most one of --baseline and "
                                "--disc-baseline")
    with _named_as_options():                 # the library's validation, before any work
        options = plan_options(
            method="algorithm2" if algorithm2 else "se2",
            baseline="disc" if disc_baseline else "se2" if baseline else None,
            time_budget=budget, iterations=iterations, sheet_margin=sheet_margin, seed=seed,
            search=search, spacing=spacing)
        replays = robustness_options(0.0 if robustness is None else robustness, trials,
                                     seed=seed)
        executed = _trajectory_options(trajectories, drive, max_speed, max_accel,
                                       max_yaw_rate, reform_speed, max_yaw_accel)
    sc = load_plan_scenario(scenario)
    with working("plan"):
        result = run_plan(sc, options)
    rob, traj, doc = _analyses(result, replays if robustness is not None else None,
                               executed, trajectories)
    _write_outputs(sc, result, traj, doc, out, plot, animate, mcap, rerun, as_json)
    _report(result, rob, doc, as_json, plot, animate, mcap, rerun)
    return 0 if result.success and (traj is None or traj.success) else 1


def _analyses(result, replays, executed, trajectories: Optional[Path]):
    """The plan's JSON form with what was asked of it: the robustness replays (``replays``
    given) and the per-robot trajectories (``executed`` given, written to their file)."""
    from ..plan.checks.robustness import monte_carlo

    doc = plan_to_dict(result)
    rob = traj = None
    if replays is not None and result.success:
        with working("robustness"):
            rob = monte_carlo(result, replays)
        doc["robustness"] = robustness_to_dict(rob)
    if executed is not None and result.success:
        from ..plan.execution.trajectories import _robot_trajectories
        with working("trajectories"):
            traj = _robot_trajectories(result, *executed)
        _write_trajectories(trajectories, traj, doc)
    return rob, traj, doc


def _write_outputs(sc, result, traj, doc: dict, out: Optional[Path], plot: Optional[Path],
                   animate: Optional[Path], mcap: Optional[Path], rerun: Optional[Path],
                   as_json: bool) -> None:
    """The recordings, the JSON file and the figures of a plan (none without a plan)."""
    if result.success:
        if traj is not None and traj.success:
            write_recordings(traj, mcap, rerun, quiet=as_json, plan=result)
        else:
            write_recordings(result, mcap, rerun, quiet=as_json)
    if out is not None:
        from ..io.files import write_text_atomic
        write_text_atomic(out, to_json(doc, indent=None) + "\n")
    if result.success and (plot is not None or animate is not None):
        from ..viz.plan import animate_plan, plot_plan
        if plot is not None:
            plot_plan(sc, result, plot, trajectories=traj)
        if animate is not None:
            animate_plan(sc, result, animate)


def _trajectory_options(path: Optional[Path], drive: str, max_speed: Optional[float],
                        max_accel: Optional[float], max_yaw_rate: Optional[float],
                        reform_speed: Optional[float], max_yaw_accel: Optional[float] = None):
    """The validated options of ``--trajectories`` (None without it): the library's
    validation, the limits it needs named as options."""
    if path is None:
        return None
    from ..plan.execution.trajectories import trajectory_options
    output_path(path, "--trajectories", (".csv", *JSON_SUFFIXES))
    if max_speed is None or max_accel is None or max_yaw_rate is None:
        name = ("max_speed" if max_speed is None else "max_accel" if max_accel is None
                else "max_yaw_rate")                          # named as options below
        raise InvalidInputError(name, "needed with --trajectories")
    extra = {k: v for k, v in (("reform_speed", reform_speed),
                               ("max_yaw_accel", max_yaw_accel)) if v is not None}
    return trajectory_options(drive, max_speed, max_accel, max_yaw_rate, **extra)


def _write_trajectories(path, traj, doc: dict) -> None:
    """Write the trajectories file and add their outcome to the plan's JSON."""
    from ..io.robot_trajectories import robot_trajectories_to_dict, save_robot_trajectories
    save_robot_trajectories(path, traj)
    summary = robot_trajectories_to_dict(traj)
    for key in ("times_s", "poses_m_rad", "object_m"):
        summary.pop(key)
    doc["trajectories"] = summary
    typer.echo(f"trajectories: {traj.message}", err=True)


@contextmanager
def _named_as_options() -> Iterator[None]:
    """The library's option errors (:mod:`taut.plan._options`) with the field named as the
    command-line option (``sheet_margin`` -> ``--sheet-margin``)."""
    try:
        yield
    except InvalidInputError as exc:
        if exc.field.startswith("--"):            # already named as an option
            raise
        name = _OPTION_OF.get(exc.field, "--" + exc.field.replace("_", "-"))
        raise InvalidInputError(name, exc.problem) from None


def _report(result, rob, doc: dict, as_json: bool, plot: Optional[Path],
            animate: Optional[Path], mcap: Optional[Path] = None,
            rerun: Optional[Path] = None) -> None:
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
        for name, path in (("--plot", plot), ("--animate", animate), ("--mcap", mcap),
                           ("--rerun", rerun)):
            if path is not None:
                typer.echo(f"taut: {name}: {path} not written: there is no plan to draw",
                           err=True)


def register(app: typer.Typer) -> None:
    """Add ``taut plan`` to the application."""
    app.command("plan")(plan_command)
