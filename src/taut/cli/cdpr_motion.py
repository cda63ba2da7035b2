"""`taut cdpr twist-set` and `taut cdpr deploy`: first-order kinematics of mobile cable
robots (FASTKIT §3: available twist set, Fig. 13) and deployment planning of their bases.

MODEL is a preset name (``fastkit``, ``ipanema``) or a YAML/JSON model file. Joint velocity
limits are FASTKIT's (eqs. 10-16) unless overridden. Errors are :class:`taut.errors.TautError`
(the top-level CLI prints ``taut: error: <field>: <problem>`` and exits 2). ``deploy`` exits
1 when it finds no verified placement (like ``taut plan`` without a plan).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

import numpy as np
import typer

from .._validate import MAX_TENSION_N, as_box, as_count, check_range
from ..errors import InvalidInputError
from ..io.serialize import deployment_to_dict, to_json, twist_set_to_dict
from ._cdpr_common import MODEL_HELP, Vec3, Vec6, given, load_robot, pose_vector, speeds
from ._paths import FIGURE_SUFFIXES, output_path
from ._progress import working

if TYPE_CHECKING:
    from ..cdpr import ModeName, MotionLimits

__all__ = ["add_commands"]

#: Largest differential-evolution iteration count `deploy` accepts (8 takes about a minute).
MAX_DEPLOY_ITERATIONS = 1000


def _limits(base_speed: Optional[float], yaw_rate: Optional[float],
            cable_speed: Optional[float]) -> MotionLimits:
    """FASTKIT's joint velocity limits (the library's) with the speeds given overridden."""
    from ..cdpr import MotionLimits, fastkit_motion_limits

    for field, value in (("--base-speed", base_speed), ("--yaw-rate", yaw_rate),
                         ("--cable-speed", cable_speed)):   # name the option, not the model
        if value is not None:
            if value <= 0:
                raise InvalidInputError(field, f"speed limits must be positive, got {value:g}")
            speeds(value, field)
    lim = fastkit_motion_limits()
    lo, hi = np.array(lim.base_min, float), np.array(lim.base_max, float)
    if yaw_rate is not None:
        lo[0], hi[0] = -yaw_rate, yaw_rate
    if base_speed is not None:
        lo[1:], hi[1:] = -base_speed, base_speed
    if cable_speed is None:
        return MotionLimits(lo, hi, lim.cable_min, lim.cable_max)
    return MotionLimits(lo, hi, -cable_speed, cable_speed)


def _twist_set(model: str, pose: Any, rpy: Any, mode: Optional[str], moving: Any,
               base_speed: Optional[float], yaw_rate: Optional[float],
               cable_speed: Optional[float], stabilisers: bool, as_json: bool,
               plot: Optional[Path]) -> None:
    from ..cdpr import available_twist_set, twist_capacities

    P = pose_vector(pose, rpy)
    lim = _limits(base_speed, yaw_rate, cable_speed)
    robot = load_robot(model, stabilisers)
    choice = given(mode=mode, moving=None if not moving else tuple(moving))
    with working("cdpr twist-set"):
        caps = twist_capacities(robot, P, lim, **choice)
        task = caps.mode.kind == "task"
        fixed = twist_capacities(robot, P, lim, "task", ()) if task else None
        ats = available_twist_set(robot, P, lim, **choice)
    kind: ModeName = "task" if task else "navigation"
    out = twist_set_to_dict(robot, P, kind, caps, fixed, int(np.isfinite(ats.h).sum()))
    series = {f"{kind}: {', '.join(caps.mode.names) or 'none'} moving": caps.positive}
    if fixed is not None:
        series["bases fixed"] = fixed.positive
    if plot is not None:
        from ..viz.cdpr_motion import plot_capacity_bars
        n = len(caps.labels)
        plot_capacity_bars(series, caps.labels, (["m/s"] * 3 + ["rad/s"] * 3)[:n],
                           f"{robot.name}: available twist set, largest speed along "
                           f"each + axis", plot)
        out["plot"] = str(plot)
    if as_json:
        typer.echo(to_json(out))
        return
    typer.echo(f"{robot.name}: available twist set at {np.round(P, 3).tolist()} ({kind} mode, "
               f"moving: {', '.join(caps.mode.names) or 'none'}; {out['facets']} facets)")
    typer.echo("axis   +max      -max" + ("    fixed +max" if fixed is not None else ""))
    for k, lab in enumerate(caps.labels):
        row = f"{lab:4s} {caps.positive[k]:8.4f}  {caps.negative[k]:8.4f}"
        if fixed is not None:
            row += f"  {fixed.positive[k]:10.4f}"
        typer.echo(row)


def _deploy(model: str, ws: Any, external_wrench: Any, twist: Any, stabilisers: bool,
            seed: Optional[int], maxiter: Optional[int], plot: Optional[Path],
            as_json: bool) -> int:
    from ..cdpr import external_wrench_box, plan_deployment

    box = as_box(ws, "workspace", allow_flat=False)
    if box[0, 2] < 0:
        raise InvalidInputError("workspace", f"zmin {box[0, 2]:g} m is below the floor "
                                "(z = 0); the platform cannot go there")
    if external_wrench is not None:
        check_range(external_wrench, "--external-wrench", MAX_TENSION_N, "N or N m")
    if twist is not None:
        speeds(twist, "twist")
    if seed is not None:
        as_count(seed, "seed", minimum=0)
    if maxiter is not None:
        as_count(maxiter, "maxiter", minimum=0, maximum=MAX_DEPLOY_ITERATIONS)
    robot = load_robot(model, stabilisers)
    D = None if external_wrench is None else \
        external_wrench_box(robot, external_wrench[:robot.dof])
    with working("cdpr deploy"):
        res = plan_deployment(robot, box, external_wrench=D,
                              required_twist=None if twist is None else twist[:robot.dof],
                              **given(seed=seed, maxiter=maxiter))
    out = deployment_to_dict(robot, res)
    note = None
    if plot is not None:
        if res.refuted:
            note = (f"nothing to plot: no placement exists, so there is no deployment to draw "
                    f"({plot} not written)")
            out["plot"] = None
            out["plot_note"] = note
        else:
            from ..viz.cdpr_motion import plot_deployment
            plot_deployment(res, plot)
            out["plot"] = str(plot)
    code = 0 if res.success else 1            # valid question, negative answer: exit 1
    if as_json:
        typer.echo(to_json(out))
        return code
    typer.echo(f"{robot.name}: deployment for workspace {box.tolist()} m: "
               + ("FEASIBLE" if res.success else "NOT FOUND"))
    if res.refuted:
        typer.echo("  " + res.message)
        typer.echo("  upper bound per cable (N): " + ", ".join(
            f"{k} {v:.2f}" for k, v in out["lift_bound"]["per_cable"].items()))
        if note:
            typer.echo("  " + note)
        return code
    for k, v in out["base_poses"].items():
        typer.echo(f"  {k}: x={v[0]} m  y={v[1]} m  theta={v[2]} rad")
    typer.echo(f"  worst capacity margin {out['margin']} over {out['points']} points "
               f"({out['feasible_points']} feasible with tipping)")
    if not res.success:
        typer.echo("  " + res.message)
    return code


def add_commands(sub: typer.Typer) -> None:
    """Add ``twist-set`` and ``deploy`` to the ``cdpr`` sub-application."""

    @sub.command("twist-set")
    def twist_set_cmd(
        model: str = typer.Argument(..., help=MODEL_HELP),
        pose: Vec3 = typer.Option(..., "--pose", help="Platform position X Y Z in m."),
        rpy: Vec3 = typer.Option((0.0, 0.0, 0.0), "--rpy",
                                 help="Platform orientation ROLL PITCH YAW in rad."),
        mode: Optional[str] = typer.Option(None, "--mode", help="task or navigation "
                                           "(default: the library's, task)."),
        moving: Optional[list[str]] = typer.Option(
            None, "--moving", help="Base moving in task mode / driver in navigation mode "
                                   "(repeatable; default the first mobile base)."),
        base_speed: Optional[float] = typer.Option(
            None, "--base-speed", help="Base speed limit, m/s (default: FASTKIT's, "
                                       "taut.cdpr.fastkit_motion_limits)."),
        yaw_rate: Optional[float] = typer.Option(
            None, "--yaw-rate", help="Base yaw-rate limit, rad/s (default: FASTKIT's)."),
        cable_speed: Optional[float] = typer.Option(
            None, "--cable-speed", help="Cable speed limit, m/s (default: FASTKIT's)."),
        stabilisers: bool = typer.Option(False, "--stabilisers",
                                         help="Deploy the stabilisers of mobile bases first "
                                              "(wider footprints against tipping)."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Bar chart (like Fig. 13; "
                                            ".png, .pdf, .svg)."),
        as_json: bool = typer.Option(False, "--json", help="Print machine-readable JSON "
                                     "instead of a table."),
    ) -> None:
        """Available twist set of the platform (FASTKIT §3.2, Fig. 13): axis capacities with
        the mode's bases moving, and (task mode) with all bases fixed."""
        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        _twist_set(model, pose, rpy, mode, moving, base_speed, yaw_rate, cable_speed,
                   stabilisers, as_json, plot)

    @sub.command("deploy")
    def deploy_cmd(
        model: str = typer.Argument(..., help=MODEL_HELP),
        workspace: Vec6 = typer.Option(..., "--workspace",
                                       help="XMIN XMAX YMIN YMAX ZMIN ZMAX in m (the order "
                                            "of `workspace --box`)."),
        external_wrench: Optional[Vec6] = typer.Option(
            None, "--external-wrench", help="Half-widths FX FY FZ (N) MX MY MZ (N m) of a box "
                                            "of extra external wrenches to resist "
                                            "everywhere."),
        twist: Optional[Vec6] = typer.Option(
            None, "--twist", help="Required twist VX VY VZ WX WY WZ (m/s, rad/s)."),
        stabilisers: bool = typer.Option(False, "--stabilisers",
                                         help="Deploy the stabilisers first."),
        seed: Optional[int] = typer.Option(
            None, "--seed", help="Seed of the differential-evolution search (>= 0; the same "
                                 "seed gives the same placement; default: the library's)."),
        maxiter: Optional[int] = typer.Option(
            None, "--maxiter", help="Differential-evolution iterations (default: the "
                                    "library's, taut.cdpr.DeploymentOptions)."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Top view (.png, .pdf, "
                                            ".svg)."),
        as_json: bool = typer.Option(False, "--json", help="Print machine-readable JSON "
                                     "instead of a table."),
    ) -> int:
        """Plan mobile-base placements making a workspace box wrench-feasible with tipping.
        A placement-independent bound on the cables' lift is checked first and proves some
        boxes impossible without a search. Exit 0 with a verified placement, 1 without, 2 on
        bad input."""
        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        return _deploy(model, workspace, external_wrench, twist, stabilisers, seed, maxiter,
                       plot, as_json)
