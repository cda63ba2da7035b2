"""`taut cdpr twist-set` and `taut cdpr deploy`: first-order kinematics of mobile cable
robots (FASTKIT §3: available twist set, Fig. 13) and deployment planning of their bases.

MODEL is a preset name (``fastkit``, ``ipanema``) or a YAML/JSON model file. Joint velocity
limits are FASTKIT's (eqs. 10-16) unless overridden. Errors are :class:`taut.errors.TautError`
(the top-level CLI prints ``taut: error: <field>: <problem>`` and exits 2). ``deploy`` exits
1 when it finds no verified placement (like ``taut plan`` without a plan).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from ..cdpr import disturbance_box
from ..cdpr.deploy import plan_deployment, workspace_box
from ..cdpr.twist import MotionLimits, available_twist_set, twist_capacities
from ..errors import InvalidInputError
from ._cdpr_common import Vec3, load_robot

__all__ = ["add_commands"]

Vec6 = tuple[float, float, float, float, float, float]


def _finite(values, field: str) -> None:
    if values is not None and any(not np.isfinite(v) for v in values):
        raise InvalidInputError(field, "contains NaN or infinite values")


def _r(x: float) -> float | None:
    return None if not np.isfinite(x) else float(round(float(x), 4))


def _twist_set(model, pose, rpy, mode, moving, base_speed, yaw_rate, cable_speed,
               stabilisers, as_json, plot) -> None:
    _finite(pose, "pose")
    _finite(rpy, "rpy")
    _finite((base_speed, yaw_rate, cable_speed), "limits")
    for field, value in (("limits.base", base_speed), ("limits.base", yaw_rate),
                         ("limits.cable", cable_speed)):
        if value <= 0:
            raise InvalidInputError(field, f"speed limits must be positive, got {value:g}")
    robot = load_robot(model, stabilisers)
    lim = MotionLimits((-yaw_rate, -base_speed, -base_speed), (yaw_rate, base_speed, base_speed),
                       -cable_speed, cable_speed)
    P = np.array([*pose, *rpy])
    mv = None if not moving else tuple(moving)
    caps = twist_capacities(robot, P, lim, mode, mv)
    out = {"model": robot.name, "pose": P.tolist(), "mode": mode,
           "moving": list(caps.mode.names), "labels": list(caps.labels),
           "positive": [_r(v) for v in caps.positive[0]],
           "negative": [_r(v) for v in caps.negative[0]]}
    series = {f"{mode}: {', '.join(caps.mode.names) or 'none'} moving": caps.positive[0]}
    if mode == "task":
        fixed = twist_capacities(robot, P, lim, "task", ())
        out["bases_fixed"] = {"positive": [_r(v) for v in fixed.positive[0]],
                              "negative": [_r(v) for v in fixed.negative[0]]}
        series["bases fixed"] = fixed.positive[0]
    ats = available_twist_set(robot, P, lim, mode, mv)
    out["facets"] = int(np.isfinite(ats.h[0]).sum())
    if plot is not None:
        from ..viz.cdpr_motion import plot_capacity_bars
        n = len(caps.labels)
        plot_capacity_bars(series, caps.labels, (["m/s"] * 3 + ["rad/s"] * 3)[:n],
                           f"{robot.name}: available twist set (+ axes)", plot)
        out["plot"] = str(plot)
    if as_json:
        typer.echo(json.dumps(out, indent=2))
        return
    typer.echo(f"{robot.name}: available twist set at {np.round(P, 3).tolist()} ({mode} mode, "
               f"moving: {', '.join(caps.mode.names) or 'none'}; {out['facets']} facets)")
    typer.echo("axis   +max      -max" + ("    fixed +max" if mode == "task" else ""))
    for k, lab in enumerate(caps.labels):
        row = f"{lab:4s} {caps.positive[0, k]:8.4f}  {caps.negative[0, k]:8.4f}"
        if mode == "task":
            row += f"  {out['bases_fixed']['positive'][k]:10.4f}"
        typer.echo(row)


def _deploy(model, ws, disturbance, twist, stabilisers, seed, maxiter, plot,
            as_json) -> int:
    _finite(ws, "workspace")
    _finite(disturbance, "disturbance")
    _finite(twist, "twist")
    box = workspace_box(np.array(ws, dtype=float))
    robot = load_robot(model, stabilisers)
    D = None if disturbance is None else disturbance_box(robot, disturbance[:robot.dof])
    res = plan_deployment(robot, box, external_wrench=D,
                          required_twist=None if twist is None else twist[:robot.dof],
                          seed=seed, maxiter=maxiter)
    lb = res.lift_bound
    out = {"model": robot.name, "workspace": box.tolist(), "feasible": res.success,
           "refuted": res.refuted,
           "base_poses": {k: [round(float(x), 4) for x in v] for k, v in res.base_poses.items()},
           "margin": _r(res.margin),
           "twist_margin": None if res.twist_margin is None else _r(res.twist_margin),
           "points": int(len(res.points)), "feasible_points": int(res.point_feasible.sum()),
           "evaluations": res.evaluations, "reason": "" if res.success else res.message,
           "lift_bound": None if lb is None else {
               "height": _r(lb.height), "bound": _r(lb.bound), "required": _r(lb.required),
               "weight": _r(lb.weight), "refutes": lb.refutes,
               "per_cable": {c.name: _r(v) for c, v in zip(robot.cables, lb.per_cable)}}}
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
        typer.echo(json.dumps(out, indent=2))
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
        model: str = typer.Argument(..., help="Preset name (fastkit, ipanema) or model file."),
        pose: Vec3 = typer.Option(..., "--pose", help="Platform position X Y Z in m."),
        rpy: Vec3 = typer.Option((0.0, 0.0, 0.0), "--rpy",
                                 help="Platform orientation ROLL PITCH YAW in rad."),
        mode: str = typer.Option("task", "--mode", help="task or navigation."),
        moving: Optional[list[str]] = typer.Option(
            None, "--moving", help="Base moving in task mode / driver in navigation mode "
                                   "(repeatable; default the first mobile base)."),
        base_speed: float = typer.Option(0.2, "--base-speed", help="Base speed limit, m/s."),
        yaw_rate: float = typer.Option(0.2, "--yaw-rate", help="Base yaw-rate limit, rad/s."),
        cable_speed: float = typer.Option(2.0, "--cable-speed", help="Cable speed limit, m/s."),
        stabilisers: bool = typer.Option(False, "--stabilisers"),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Bar chart (like Fig. 13)."),
        as_json: bool = typer.Option(False, "--json", help="Machine-readable output."),
    ) -> None:
        """Available twist set of the platform (FASTKIT §3.2, Fig. 13): axis capacities with
        the mode's bases moving, and (task mode) with all bases fixed."""
        _twist_set(model, pose, rpy, mode, moving, base_speed, yaw_rate, cable_speed,
                   stabilisers, as_json, plot)

    @sub.command("deploy")
    def deploy_cmd(
        model: str = typer.Argument(..., help="Preset name (fastkit, ipanema) or model file."),
        workspace: Vec6 = typer.Option(..., "--workspace",
                                       help="XMIN XMAX YMIN YMAX ZMIN ZMAX in m."),
        disturbance: Optional[Vec6] = typer.Option(
            None, "--disturbance", help="Half-widths FX FY FZ MX MY MZ (N, N m) of an extra "
                                        "wrench box to resist everywhere."),
        twist: Optional[Vec6] = typer.Option(
            None, "--twist", help="Required twist VX VY VZ WX WY WZ (m/s, rad/s)."),
        stabilisers: bool = typer.Option(False, "--stabilisers",
                                         help="Deploy the stabilisers first."),
        seed: int = typer.Option(0, "--seed"),
        maxiter: int = typer.Option(8, "--maxiter", help="Differential-evolution iterations."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Top view (PNG)."),
        as_json: bool = typer.Option(False, "--json", help="Machine-readable output."),
    ) -> int:
        """Plan mobile-base placements making a workspace box wrench-feasible with tipping.
        A placement-independent bound on the cables' lift is checked first and proves some
        boxes impossible without a search. Exit 0 with a verified placement, 1 without."""
        return _deploy(model, workspace, disturbance, twist, stabilisers, seed, maxiter, plot,
                       as_json)
