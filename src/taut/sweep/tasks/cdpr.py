"""``cdpr_workspace`` and ``cdpr_deployment``: a mobile cable robot over base placements,
payloads and tension limits (FASTKIT paper §3-4).

``base_separation`` moves the two mobile bases symmetrically along the line joining them
(their headings kept), so the distance between their frames becomes the given value, m.
``payload`` replaces the payload mass, kg; ``t_max`` replaces every cable's maximum tension,
N. Grid points outside the frame spanned by the exit points (bases moved closer) count as
not feasible. A point whose modified model is invalid (e.g. ``t_max`` below ``t_min``) keeps NaN
results and its reason in ``message``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...errors import SweepError, TautError
from ..task import Columns, Task

__all__ = ["CDPR_WORKSPACE", "CDPR_DEPLOYMENT", "variant"]


@dataclass(frozen=True, eq=False)
class _Context:
    robot: Any
    box: np.ndarray             # (2, 3) m
    grid: tuple[int, int, int]


def _prepare(spec: Any, robot: Any) -> _Context:
    opts = dict(spec.options)
    box = opts.get("box")
    if box is None:
        if robot.desired_workspace is None:
            raise SweepError("options.box", "the model has no desired workspace; give a box "
                             "[[xmin, ymin, zmin], [xmax, ymax, zmax]] in m")
        box = robot.desired_workspace
    box = np.asarray(box, dtype=float)
    if box.shape != (2, 3) or not np.all(np.isfinite(box)) or np.any(box[0] > box[1]):
        raise SweepError("options.box", "must be [[xmin, ymin, zmin], [xmax, ymax, zmax]] "
                         "with min <= max, m")
    grid = tuple(int(g) for g in opts.get("grid", (21, 1, 9)))
    if len(grid) != 3 or min(grid) < 1:
        raise SweepError("options.grid", "must be three positive integers nx ny nz")
    return _Context(robot, box, (grid[0], grid[1], grid[2]))


def _defaults(ctx: _Context) -> dict[str, float]:
    robot = ctx.robot
    mobile = [b for b in robot.bases if b.mobile]
    sep = (float(np.linalg.norm(np.asarray(mobile[0].pose[:2]) - mobile[1].pose[:2]))
           if len(mobile) == 2 else np.nan)
    return {"base_separation": sep, "payload": float(robot.payload.mass),
            "t_max": float(np.max(robot.t_max)), "stabilisers": 0.0}


def variant(robot: Any, separation: float, payload: float, t_max: float, *,
            stabilisers: bool) -> Any:
    """The robot with its two mobile bases ``separation`` m apart, payload mass and cable
    ``t_max`` replaced (stabilisers deployed when asked)."""
    from ...cdpr import place_bases, with_stabilisers

    mobile = [b for b in robot.bases if b.mobile]
    if np.isfinite(separation):
        if len(mobile) != 2:
            raise SweepError("parameters.base_separation", "needs a model with exactly two "
                             "mobile bases")
        p0, p1 = np.asarray(mobile[0].pose, float), np.asarray(mobile[1].pose, float)
        mid, axis = 0.5 * (p0[:2] + p1[:2]), p1[:2] - p0[:2]
        axis = axis / np.linalg.norm(axis)
        poses = np.array([[*(mid - 0.5 * separation * axis), p0[2]],
                          [*(mid + 0.5 * separation * axis), p1[2]]])
        robot = place_bases(robot, poses)
    robot = replace(robot, payload=replace(robot.payload, mass=payload),
                    cables=tuple(replace(c, t_max=t_max) for c in robot.cables))
    return with_stabilisers(robot) if stabilisers else robot


def _run_workspace(ctx: _Context, cols: Columns, seeds: np.ndarray) -> Columns:
    from ...cdpr import grid_points, wrench_feasible_workspace

    b = len(seeds)
    out: Columns = {"coverage": np.full(b, np.nan), "coverage_tipping": np.full(b, np.nan),
                    "n_points": np.zeros(b, dtype=np.int64),
                    "n_outside": np.zeros(b, dtype=np.int64),
                    "message": np.full(b, "", dtype=object)}
    points, _ = grid_points(ctx.box, ctx.grid)
    for k in range(b):
        try:
            robot = variant(ctx.robot, cols["base_separation"][k], cols["payload"][k],
                            cols["t_max"][k], stabilisers=bool(cols["stabilisers"][k]))
            lo, hi = np.asarray(robot.bounds, float)
            inside = np.all((points >= lo) & (points <= hi), axis=1)
            feas = np.zeros(len(points), bool)
            feas_t = np.zeros(len(points), bool)
            if inside.any():
                ws = wrench_feasible_workspace(robot, points[inside])
                feas[inside] = ws.feasible
                feas_t[inside] = ws.feasible if ws.feasible_tipping is None \
                    else ws.feasible_tipping
        except SweepError:
            raise
        except TautError as exc:
            out["message"][k] = str(exc)
            continue
        out["coverage"][k] = feas.mean()
        out["coverage_tipping"][k] = feas_t.mean()
        out["n_points"][k] = len(points)
        out["n_outside"][k] = int((~inside).sum())
    return out


def _run_deployment(ctx: _Context, cols: Columns, seeds: np.ndarray) -> Columns:
    from ...cdpr import plan_deployment

    b = len(seeds)
    out: Columns = {"success": np.zeros(b, dtype=bool), "status": np.full(b, "", dtype=object),
                    "margin": np.full(b, np.nan), "message": np.full(b, "", dtype=object)}
    for k in range(b):
        box = ctx.box.copy()
        if np.isfinite(cols["z_max"][k]):
            box[1, 2] = cols["z_max"][k]
        try:
            robot = variant(ctx.robot, np.nan, cols["payload"][k], cols["t_max"][k],
                            stabilisers=bool(cols["stabilisers"][k]))
            res = plan_deployment(robot, box)
        except SweepError:
            raise
        except TautError as exc:
            out["message"][k] = str(exc)
            continue
        out["success"][k], out["status"][k] = bool(res.success), str(res.status)
        out["margin"][k], out["message"][k] = float(res.margin), str(res.message)
    return out


_MODEL_PARAMETERS = {
    "payload": "payload mass, kg",
    "t_max": "maximum tension of every cable, N",
    "stabilisers": "1 to deploy the bases' stabilisers, 0 not to",
}

CDPR_WORKSPACE = Task(
    name="cdpr_workspace",
    summary="wrench-feasible fraction of a workspace grid, with and without tipping",
    parameters={"base_separation": "distance between the two mobile bases' frames, m",
                **_MODEL_PARAMETERS},
    outputs={"coverage": "fraction of the box's grid points wrench-feasible (limits only; "
                         "points outside the frame count as infeasible)",
             "coverage_tipping": "fraction also free of tipping (FASTKIT eqs. 21-23)",
             "n_points": "grid points of the box",
             "n_outside": "grid points outside the frame spanned by the exit points",
             "message": "why a point has no result (empty when it has one)"},
    defaults=_defaults,
    default_chunk=4,
    needs_base="cdpr model",
    prepare=_prepare,
    run=_run_workspace,
)

CDPR_DEPLOYMENT = Task(
    name="cdpr_deployment",
    summary="whether base placements exist that make a workspace box wrench-feasible",
    parameters={"z_max": "top of the workspace box, m (default: the box's)",
                **_MODEL_PARAMETERS},
    outputs={"success": "a verified deployment was found",
             "status": "the result's status (ok, refuted, infeasible, ...)",
             "margin": "worst capacity margin of the deployment found",
             "message": "the result's message"},
    defaults=lambda ctx: {**_defaults(ctx), "z_max": float(ctx.box[1, 2])},
    default_chunk=1,
    needs_base="cdpr model",
    prepare=_prepare,
    run=_run_deployment,
)
