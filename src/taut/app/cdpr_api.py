"""JSON endpoints of the cable-robot explorer: load a preset or model file, evaluate a
platform pose (tensions against their limits, tipping margins of the mobile bases,
wrench feasibility with and without tipping, the platform's outline in the side and top
views) and a slice of the wrench-feasible workspace.

Every verdict and message is a library result's: :func:`taut.cdpr.distribute_tensions`
with the library's defaults (``feasible``, ``binding``, ``message``) and with the tension
limits alone (``feasible_limits``), :func:`taut.cdpr.tipping_moments` (per-base margins),
:func:`taut.cdpr.cable_state` and :func:`taut.cdpr.wrench_feasible_workspace`. SI units:
m, rad, N, N m.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import yaml

from ..cdpr import (CableRobot, cable_state, distribute_tensions, grid_points,
                    tipping_moments, wrench_feasible_workspace, with_stabilisers)
from ..cdpr import METHODS as TENSION_METHODS
from .._geometry import convex_hull_2d
from .._validate import as_choice
from ..errors import InfeasiblePoseError, InvalidInputError
from ..io import cdpr_model_from_mapping
from ..io.serialize import json_ready
from .catalog import Catalog
from .payload import ModelCache, field, mapping_from_upload, numbers

__all__ = ["CdprAPI"]

#: Most grid points of one workspace slice (keeps a slice under about a second).
MAX_SLICE_POINTS = 4000


def _build(key: dict[str, Any]) -> CableRobot:
    robot = cdpr_model_from_mapping(key["model"])
    return with_stabilisers(robot) if key["stabilisers"] else robot


def geometry(robot: CableRobot) -> dict[str, Any]:
    """Fixed parts for drawing: frame box, desired workspace, exit points, bases with
    their support polygons in the world frame, cable names and tension limits."""
    bases = []
    for b in robot.bases:
        poly = b.support_polygon
        world = None if poly is None else \
            b.to_world(np.column_stack([poly, np.zeros(len(poly))]))[:, :2].tolist()
        bases.append({"name": b.name, "mobile": bool(b.mobile), "support": world,
                      "exits": b.to_world(b.exit_local).tolist()})
    dw = robot.desired_workspace
    r: Any = robot            # exits_world, cable_base, t_min, t_max: set when validated
    return {"name": robot.name, "bounds": np.asarray(robot.bounds).tolist(),
            "desired_workspace": None if dw is None else np.asarray(dw).tolist(),
            "exits": r.exits_world.tolist(), "bases": bases,
            "cables": [c.name for c in robot.cables], "cable_base": r.cable_base.tolist(),
            "t_min": r.t_min.tolist(), "t_max": r.t_max.tolist(),
            "has_tipping": bool(robot.has_tipping), "methods": list(TENSION_METHODS)}


def _pose(body: dict[str, Any]) -> np.ndarray:
    pose = numbers(field(body, "pose", list), "pose", 1)
    if pose.shape != (6,) or not np.all(np.isfinite(pose)):
        raise InvalidInputError("pose", "must be 6 finite numbers x y z roll pitch yaw "
                                        "(m, rad)")
    return pose


def outline(attachments: np.ndarray) -> dict[str, list[list[float]]]:
    """The platform as the 2D views draw it: the convex hull (counter-clockwise, the
    library's :func:`~taut._geometry.convex_hull_2d`) of the attachment points (m, world
    frame, shape (m, 3)) projected on the x-z plane (``"xz"``, the side view) and on the
    x-y plane (``"xy"``, the top view); rows are (horizontal, vertical) points in m.
    Attachments that meet in one point (a point-mass platform) give that point."""
    return {name: convex_hull_2d(attachments[:, [0, k]]).tolist()
            for name, k in (("xz", 2), ("xy", 1))}


class CdprAPI:
    """The cable-robot explorer's endpoints (models cached by their mapping)."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog
        self.models = ModelCache(_build)

    def _robot(self, body: dict[str, Any]) -> CableRobot:
        return self.models.get({"model": field(body, "model", dict),
                                "stabilisers": field(body, "stabilisers", bool, default=False)})

    def load(self, body: dict[str, Any]) -> dict[str, Any]:
        """``{"example": preset or file name}``, an upload ``{"text", "filename"}`` or
        ``{"model": mapping}`` -> the model mapping and its drawing geometry."""
        if "example" in body:
            data = self.catalog.mapping("cdpr", field(body, "example", str))
        elif "text" in body:
            data = mapping_from_upload(field(body, "text", str),
                                       field(body, "filename", str, default="upload.yaml"))
        else:
            data = field(body, "model", dict)
        robot = self.models.get({"model": data, "stabilisers": False})
        return {"model": data, "geometry": geometry(robot)}

    def yaml(self, body: dict[str, Any]) -> dict[str, Any]:
        """The model file, headed by the ``taut cdpr tensions`` command for the pose (the
        same library defaults as :meth:`state`). The model (its name included) is written
        by the YAML serializer only; the comment holds nothing but validated numbers and
        choices, so no text from the request can add a line or a key."""
        self._robot(body)
        pose = _pose(body)
        num = [np.format_float_positional(v, trim="-") for v in pose]   # shortest exact
        cmd = f"taut cdpr tensions FILE --pose {' '.join(num[:3])} --rpy {' '.join(num[3:])}"
        method = field(body, "method", str, default=None)
        if method is not None:
            cmd += " --method " + as_choice(method, tuple(TENSION_METHODS), "method")
        if field(body, "stabilisers", bool, default=False):
            cmd += " --stabilisers"
        text = ("# cable-robot model saved by `taut app`; the pose shown:\n"
                f"#   {cmd}\n" + yaml.safe_dump(field(body, "model", dict), sort_keys=False,
                                               default_flow_style=None))
        return {"yaml": text, "filename": "cdpr_model.yaml"}

    def state(self, body: dict[str, Any]) -> dict[str, Any]:
        """Statics at ``pose`` [x, y, z, roll, pitch, yaw]: tensions, limits, tipping
        margins, feasibility, the platform's outline in the views (``outline_m``, see
        :func:`outline`); a pose outside the frame box is flagged, not an error.
        ``method`` (optional) is passed on; omitted, the library's default is used."""
        robot = self._robot(body)
        pose = _pose(body)
        method = field(body, "method", str, default=None)
        st = cable_state(robot, pose[None], validated=True)
        attach = pose[:3] + st.r[0]
        out: dict[str, Any] = {"pose": pose.tolist(), "attachments": attach.tolist(),
                               "outline_m": outline(attach), "in_frame": True}
        try:
            res = distribute_tensions(robot, pose, **({} if method is None else
                                                      {"method": method}))
        except InfeasiblePoseError as exc:
            return dict(out, in_frame=False, feasible=False, feasible_limits=False,
                        message=str(exc), tensions=None, shown="none", margins=[])
        limits = distribute_tensions(robot, pose, res.method, tipping=False, sliding=False)
        checked = ["limits"] + ["tipping"] * res.tipping + ["sliding"] * res.sliding
        shown, label = ((res, "with " + " and ".join(checked)) if res.success else
                        (limits, "limits only"))
        if not limits.success and not np.all(np.isfinite(limits.tensions)):
            # No solution at all: show the closed form's best attempt and its violations.
            shown = distribute_tensions(robot, pose, "closed_form", tipping=False,
                                        sliding=False)
            label = "closed-form attempt (violates the limits)"
        t = shown.tensions
        margins = []
        if robot.has_tipping and (res.success or limits.success):   # a valid distribution
            tm = tipping_moments(robot, pose, t)
            margins = [{"base": b.name, "margin": -float(tm.base_moment[k]),
                        "stable": bool(tm.base_stable[k])}
                       for k, b in enumerate(robot.bases) if np.isfinite(tm.base_moment[k])]
        return dict(out, feasible=bool(res.success), feasible_limits=bool(limits.success),
                    binding=str(res.binding), message=res.message,
                    tensions=json_ready(np.ravel(t)), shown=label, margins=margins,
                    method=res.method)

    def workspace(self, body: dict[str, Any]) -> dict[str, Any]:
        """Wrench-feasible slice: ``plane`` "xz" (at y = ``offset``) or "xy" (at z =
        ``offset``) over the frame box, ``n`` = [columns, rows], orientation ``rpy``."""
        robot = self._robot(body)
        plane = as_choice(field(body, "plane", str, default="xz"), ("xz", "xy"), "plane")
        n = field(body, "n", list, default=[41, 21])
        if (len(n) != 2 or not all(isinstance(k, int) and k >= 2 for k in n)
                or n[0] * n[1] > MAX_SLICE_POINTS):
            raise InvalidInputError("n", f"must be two integers >= 2 with at most "
                                         f"{MAX_SLICE_POINTS} points in all")
        rpy = numbers(field(body, "rpy", list, default=[0.0, 0.0, 0.0]), "rpy", 1,
                      length=3)
        if not np.all(np.isfinite(rpy)):
            raise InvalidInputError("rpy", "must be 3 finite angles, rad")
        box = np.array(robot.bounds, dtype=float)
        flat = 1 if plane == "xz" else 2
        offset = float(field(body, "offset", (int, float), default=0.0))
        box[:, flat] = np.clip(offset, box[0, flat], box[1, flat])
        shape = [n[0], 1, n[1]] if plane == "xz" else [n[0], n[1], 1]
        pts, eff = grid_points(box, shape)
        ws = wrench_feasible_workspace(robot, pts, orientations=[rpy], shape=eff)
        cols = 2 if plane == "xz" else 1
        grid = (n[0], n[1])

        def rows(flags: np.ndarray | None) -> list[list[bool]] | None:
            return None if flags is None else flags.reshape(grid).T.tolist()

        return {"plane": plane, "offset": float(box[0, flat]),
                "a": np.unique(pts[:, 0]).tolist(), "b": np.unique(pts[:, cols]).tolist(),
                "feasible": rows(ws.feasible), "feasible_tipping": rows(ws.feasible_tipping),
                "coverage": ws.coverage, "coverage_tipping": ws.coverage_tipping}
