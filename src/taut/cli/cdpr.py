"""`taut cdpr ...`: statics of cable-driven parallel robots on fixed frames and mobile bases
(FASTKIT paper, §4): tension distribution, available wrench set, wrench-feasible workspace.

MODEL is a preset name (``fastkit``, ``ipanema``) or a YAML/JSON model file. Poses are given
as ``--pose X Y Z`` (m) and optionally ``--rpy ROLL PITCH YAW`` (rad).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer

from .._validate import MAX_CDPR_LENGTH_M, MAX_TENSION_N, as_box, as_choice, as_count, check_range
from ..errors import InvalidInputError
from ..io.serialize import tensions_to_dict, to_json, workspace_to_dict, wrench_set_to_dict
from ._cdpr_common import MODEL_HELP, Vec3, given, load_robot, pose_vector
from ._paths import FIGURE_SUFFIXES, output_path
from ._progress import working
from .cdpr_motion import add_commands
from .cdpr_sim import add_simulate
from .cdpr_mission import add_mission

__all__ = ["register"]

_POSE_HELP = "Platform position X Y Z in m."
_RPY_HELP = "Platform orientation ROLL PITCH YAW in rad (Rz(yaw) Ry(pitch) Rx(roll))."


# Options shared by the three commands (typer option metadata can be reused).
_MODEL_ARG = typer.Argument(..., help=MODEL_HELP)
_POSE_OPT = typer.Option(..., "--pose", help=_POSE_HELP)
_RPY_OPT = typer.Option((0.0, 0.0, 0.0), "--rpy", help=_RPY_HELP)
_STAB_OPT = typer.Option(False, "--stabilisers", help="Deploy the stabilisers of mobile bases.")
_JSON_OPT = typer.Option(False, "--json", help="Print machine-readable JSON instead of a "
                         "table.")


def _table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(h), *(len(r[k]) for r in rows)) if rows else len(h)
              for k, h in enumerate(headers)]
    line = "  ".join(h.rjust(w) for h, w in zip(headers, widths))
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join(out)


def _tensions(model: str, pose: Any, rpy: Any, method: Optional[str],
              tipping: Optional[bool], stabilisers: bool, as_json: bool) -> int:
    """Exit 0 when the pose is wrench-feasible, 1 when it is not: the verdict, the binding
    condition and the message are the library result's (options not given take the
    library's defaults)."""
    from ..cdpr import METHODS, distribute_tensions, tipping_moments

    P = pose_vector(pose, rpy)
    robot = load_robot(model, stabilisers)
    if method is not None:
        as_choice(method, METHODS, "--method")
    with working("cdpr tensions"):
        res = distribute_tensions(robot, P, **given(method=method, tipping=tipping))
    code = 0 if res.success else 1
    if as_json:
        typer.echo(to_json(tensions_to_dict(robot, P, res)))
        return code
    note = "" if not res.tipping else (
        "  (tipping checked)" if res.method == "closed_form" else "  (tipping imposed)")
    typer.echo(f"{robot.name}: pose {P.round(4).tolist()}  method {res.method}{note}")
    t = res.tensions
    if not np.all(np.isfinite(t)):
        typer.echo(res.message)
        return code
    rows = [[c.name, f"{v:.3f}", f"{lo:g}", f"{hi:g}", "ok" if inside else "!"]
            for c, v, lo, hi, inside in zip(robot.cables, t, robot.t_min, robot.t_max,
                                            res.within_limits)]
    typer.echo(_table(["cable", "tension [N]", "min", "max", ""], rows))
    typer.echo(f"feasible: {'yes' if res.success else 'no'}   "
               f"residual max|W t + w_e| = {res.residual:.2e}")
    if robot.has_tipping:
        tip = tipping_moments(robot, P, t)
        for k, base in enumerate(robot.bases):
            if np.isfinite(tip.base_moment[k]):
                typer.echo(f"base {base.name}: largest edge moment {tip.base_moment[k]:.2f} "
                           f"N m ({'stable' if tip.base_stable[k] else 'TIPS'})")
    typer.echo(res.message)
    return code


def _wrench_set(model: str, pose: Any, rpy: Any, external_wrench: Any, stabilisers: bool,
                as_json: bool, plot: Optional[Path] = None) -> None:
    from ..cdpr import (available_wrench_set, axis_capacities, capacity_margin,
                        external_wrench_box, wrench_feasible)

    P = pose_vector(pose, rpy)
    robot = load_robot(model, stabilisers)
    D = None
    if external_wrench is not None:
        hw = np.zeros(robot.dof)
        vals = check_range(external_wrench, "--external-wrench", MAX_TENSION_N, "N or N m")
        hw[:min(len(vals), robot.dof)] = vals[:robot.dof]
        D = external_wrench_box(robot, hw)
    modes: dict[str, dict[str, Any]] = {}
    with working("cdpr wrench-set"):
        for tip in ([False, True] if robot.has_tipping else [False]):
            modes["with_tipping" if tip else "tension_limits_only"] = {
                "capacities": axis_capacities(robot, P, tipping=tip),
                "halfspaces": available_wrench_set(robot, P, tipping=tip).facets(),
                "margin": float(capacity_margin(robot, P, D, tipping=tip)),
                "gravity_feasible": bool(wrench_feasible(robot, P, tipping=tip))}
    out = wrench_set_to_dict(robot, P, modes)
    caps = {key: m["capacities"] for key, m in modes.items()}
    if plot is not None:
        from ..viz.cdpr import plot_axis_capacities
        import matplotlib.pyplot as plt
        fig = plot_axis_capacities(caps["tension_limits_only"], caps.get("with_tipping"), plot,
                                   title=f"{robot.name}: wrench capability at "
                                         f"{np.round(P[:3], 3).tolist()} m (per axis the "
                                         f"smaller of the + and - directions)")
        plt.close(fig)
        out["plot"] = str(plot)
    if as_json:
        typer.echo(to_json(out))
        return
    typer.echo(f"{robot.name}: available wrench set at pose {P.round(4).tolist()}")
    typer.echo("largest extra external wrench on top of the platform and payload weight "
               "(N, N m):")
    rows = []
    for lab_i, lab in enumerate(caps["tension_limits_only"].labels):
        row = [lab]
        for key in caps:
            row += [f"{caps[key].positive[lab_i]:.2f}", f"{caps[key].negative[lab_i]:.2f}"]
        rows.append(row)
    head = ["axis", "+ (cables)", "- (cables)"]
    if len(caps) == 2:
        head += ["+ (tipping)", "- (tipping)"]
    typer.echo(_table(head, rows))
    for key in caps:
        o = out[key]
        typer.echo(f"{key.replace('_', ' ')}: weight held: "
                   f"{'yes' if o['gravity_feasible'] else 'no'}; "
                   f"{len(o['halfspaces']['h'])} half-spaces (some may be redundant); margin "
                   f"{o['capacity_margin'] if o['capacity_margin'] is not None else '-inf'}")
    if plot is not None:
        typer.echo(f"figure written to {plot}")


def _orientations(rpy: Any, sweep: float) -> np.ndarray:
    """The orientation ``rpy`` and, when ``sweep`` > 0, ``rpy`` +- sweep about each axis."""
    base = pose_vector((0.0, 0.0, 0.0), rpy)[3:][None]
    if not np.isfinite(sweep) or sweep < 0 or sweep > np.pi:
        raise InvalidInputError("sweep", "must be a finite angle in [0, pi] rad")
    if sweep == 0:
        return base
    steps = np.vstack([np.zeros(3), sweep * np.eye(3), -sweep * np.eye(3)])
    return base + steps


def _workspace(model: str, grid: Any, box: Any, rpy: Any, plot: Optional[Path],
               stabilisers: bool, as_json: bool, sweep: float = 0.0,
               closure: Optional[bool] = None) -> None:
    from ..cdpr import grid_points, wrench_feasible_workspace

    nx, ny, nz = (as_count(n, "grid", minimum=1) for n in grid)
    ori = _orientations(rpy, sweep)
    region = None if box is None else as_box(box, "box", limit=MAX_CDPR_LENGTH_M)
    robot = load_robot(model, stabilisers)
    if region is None:
        region = robot.desired_workspace if robot.desired_workspace is not None \
            else robot.bounds
    pts, shape = grid_points(region, (nx, ny, nz))
    with working("cdpr workspace") as update:
        ws = wrench_feasible_workspace(robot, pts, orientations=ori, shape=shape,
                                       progress=update, **given(closure=closure))
    if plot is not None:
        from ..viz.cdpr import plot_workspace
        from ..viz.cdpr_binding import plot_binding
        import matplotlib.pyplot as plt
        three_d = min(shape) > 1              # a 3D grid: the binding condition as colour
        fig = plot_binding(ws, robot, plot, view="3d") if three_d else \
            plot_workspace(ws, robot, plot)
        plt.close(fig)
    if as_json:
        typer.echo(to_json(workspace_to_dict(robot, region, ws, len(pts), plot)))
        return
    typer.echo(f"{robot.name}: wrench-feasible workspace on a {'x'.join(map(str, shape))} grid "
               f"over {np.round(region, 3).tolist()} m"
               + (f", feasible at all {len(ori)} orientations" if len(ori) > 1 else ""))
    rows = [["tension limits", str(int(ws.feasible.sum())), f"{100 * ws.coverage:.1f} %"]]
    if ws.feasible_tipping is not None and ws.coverage_tipping is not None:
        rows.append(["+ tipping", str(int(ws.feasible_tipping.sum())),
                     f"{100 * ws.coverage_tipping:.1f} %"])
    rows += _extra_rows(ws)
    typer.echo(_table(["constraints", f"feasible of {len(pts)}", "coverage"], rows))
    if plot is not None:
        typer.echo(f"figure written to {plot}")


def _extra_rows(ws: Any) -> list[list[str]]:
    """Table rows of the conditions beyond limits and tipping the result carries."""
    rows = []
    if ws.feasible_sliding is not None and ws.coverage_sliding is not None:
        rows.append(["+ sliding", str(int(ws.feasible_sliding.sum())),
                     f"{100 * ws.coverage_sliding:.1f} %"])
    if ws.inside_exits is not None and ws.coverage_inside is not None:
        rows.append(["+ inside exits' box", str(int((ws.binding == "").sum())),
                     f"{100 * ws.coverage_inside:.1f} %"])
    if ws.closure is not None and ws.coverage_closure is not None:
        rows.append(["wrench closure", str(int(ws.closure.sum())),
                     f"{100 * ws.coverage_closure:.1f} %"])
    return rows


def register(app: typer.Typer) -> None:
    """Add the ``cdpr`` sub-app to the `taut` app."""
    sub = typer.Typer(help="Cable-driven parallel robots (fixed or on mobile bases): "
                           "tensions, wrench sets, workspaces, twist sets, deployment.",
                      no_args_is_help=True)

    @sub.command("tensions")
    def tensions_cmd(
        model: str = _MODEL_ARG,
        pose: Vec3 = _POSE_OPT,
        rpy: Vec3 = _RPY_OPT,
        method: Optional[str] = typer.Option(
            None, "--method", help="Tension distribution method: closed_form, lp_min_sum, "
                                   "lp_min_max or qp_min_norm (default: the library's, "
                                   "taut.cdpr.distribute_tensions)."),
        tipping: Optional[bool] = typer.Option(
            None, "--tipping/--no-tipping", help="Consider the tipping of the mobile bases "
                                                 "(FASTKIT eqs. 21-23; imposed by LP/QP, "
                                                 "checked by closed_form) or not (default: "
                                                 "the library's, considered)."),
        stabilisers: bool = _STAB_OPT,
        as_json: bool = _JSON_OPT,
    ) -> int:
        """Cable tensions holding platform and payload at a pose (FASTKIT eqs. 17-23).
        Exit 0 when the pose is wrench-feasible (tensions within the limits, no mobile base
        tips or slides), 1 when it is not (the last line says why), 2 on bad input."""
        return _tensions(model, pose, rpy, method, tipping, stabilisers, as_json)

    @sub.command("wrench-set")
    def wrench_set_cmd(
        model: str = _MODEL_ARG,
        pose: Vec3 = _POSE_OPT,
        rpy: Vec3 = _RPY_OPT,
        external_wrench: Optional[tuple[float, float, float, float, float, float]] = \
            typer.Option(None, "--external-wrench", help="Half-widths FX FY FZ (N) MX MY MZ "
                                                         "(N m) of a box of extra external "
                                                         "wrenches for the capacity margin."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write a bar chart of the "
                                            "axis capacities (like FASTKIT Fig. 14; .png, "
                                            ".pdf, .svg)."),
        stabilisers: bool = _STAB_OPT,
        as_json: bool = _JSON_OPT,
    ) -> None:
        """Available wrench set at a pose: axis capacities, margin, half-spaces (eq. 24)."""
        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        _wrench_set(model, pose, rpy, external_wrench, stabilisers, as_json, plot)

    @sub.command("workspace")
    def workspace_cmd(
        model: str = _MODEL_ARG,
        grid: tuple[int, int, int] = typer.Option((41, 1, 21), "--grid",
                                                  help="Points per axis NX NY NZ."),
        box: Optional[tuple[float, float, float, float, float, float]] = typer.Option(
            None, "--box", help="XMIN XMAX YMIN YMAX ZMIN ZMAX in m, the order of `deploy "
                                "--workspace` (default: the model's desired workspace, else "
                                "its frame)."),
        rpy: Vec3 = _RPY_OPT,
        sweep: float = typer.Option(0.0, "--sweep", help="Also require feasibility at the "
                                    "orientation +- SWEEP rad about each axis (7 in all)."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write a figure (.png, "
                                            ".pdf, .svg)."),
        stabilisers: bool = _STAB_OPT,
        as_json: bool = _JSON_OPT,
        closure: Optional[bool] = typer.Option(
            None, "--closure/--no-closure", help="Also compute the wrench-closure workspace "
                                                 "(positive tensions, no limits; exact LP "
                                                 "per pose; default: the library's, not)."),
    ) -> None:
        """Wrench-feasible workspace with and without tipping; coverage of the desired one."""
        plot = output_path(plot, "--plot", FIGURE_SUFFIXES)
        _workspace(model, grid, box, rpy, plot, stabilisers, as_json, sweep, closure)

    add_commands(sub)
    add_simulate(sub)
    add_mission(sub)
    app.add_typer(sub, name="cdpr")
