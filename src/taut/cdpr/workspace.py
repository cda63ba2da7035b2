"""Wrench-feasible workspace (WFW, FASTKIT §4) over grids of platform positions, with and
without the tipping constraints of mobile bases, for one orientation or a sweep of them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_array
from ..errors import InvalidInputError
from ._common import renamed_keyword
from ._tol import BOX_REL
from .model import CableRobot
from .wrench_set import wrench_feasible

__all__ = ["WorkspaceResult", "grid_points", "wrench_feasible_workspace"]


def grid_points(box: ArrayLike, shape: ArrayLike) -> tuple[np.ndarray, tuple[int, int, int]]:
    """Regular grid over ``box`` ([[xmin, ymin, zmin], [xmax, ymax, zmax]], m) with ``shape``
    (nx, ny, nz) points per axis (a flat axis gets one point). Returns points (P, 3) in
    C order (x slowest) and the effective shape."""
    b = as_array(box, "box", shape=(2, 3))
    sh = np.asarray(shape, dtype=float)
    if sh.shape != (3,) or np.any(sh < 1) or np.any(sh != np.round(sh)):
        raise InvalidInputError("grid", "must be three positive integers nx ny nz")
    nx, ny, nz = (int(n) if b[1, k] > b[0, k] else 1 for k, n in enumerate(sh))
    eff = (nx, ny, nz)
    axes = [np.linspace(b[0, k], b[1, k], eff[k]) if eff[k] > 1 else
            np.array([0.5 * (b[0, k] + b[1, k])]) for k in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]), eff


@dataclass(frozen=True)
class WorkspaceResult:
    """Wrench-feasible workspace on a set of positions.

    Attributes
    ----------
    points : (P, 3)
        Platform positions, m.
    orientations : (O, 3)
        Roll, pitch, yaw swept at every position, rad.
    feasible : (P,) bool
        Feasible at every orientation within tension limits (eq. 20) only.
    feasible_tipping : (P,) bool or None
        Also without tipping any mobile base (eqs. 21-23); None for a fixed frame.
    per_orientation : (P, O) bool
        ``feasible_tipping`` (or ``feasible``) orientation by orientation.
    shape : tuple or None
        Grid shape when the points came from :func:`grid_points`.
    coverage : float
        Fraction of positions (those inside the desired workspace, if the robot has one)
        feasible without tipping.
    coverage_tipping : float or None
        The same with tipping.
    """

    points: np.ndarray
    orientations: np.ndarray
    feasible: np.ndarray
    feasible_tipping: np.ndarray | None
    per_orientation: np.ndarray
    shape: tuple[int, ...] | None
    coverage: float
    coverage_tipping: float | None


def wrench_feasible_workspace(robot: CableRobot, points: ArrayLike, *,
                              orientations: ArrayLike | None = None,
                              external_wrench: ArrayLike | None = None,
                              shape: tuple[int, ...] | None = None, chunk: int = 2048,
                              progress: Callable[[int, int], None] | None = None,
                              disturbance: ArrayLike | None = None) -> WorkspaceResult:
    """Evaluate the wrench-feasible workspace at positions ``points`` (P, 3), m.

    A position belongs to the WFW when, at every orientation of ``orientations`` ((O, 3)
    roll-pitch-yaw, rad; default level), the cables can hold platform and payload weight
    plus every wrench of ``external_wrench`` ((V, n), N and N m; ``disturbance`` is its
    deprecated name) within their tension limits,
    and, for ``feasible_tipping``, without tipping a mobile base. Vectorised (see
    :func:`taut.cdpr.wrench_set.wrench_feasible`). ``progress(done, total)`` is called after
    each block of ``chunk`` poses. Positions outside the frame raise :class:`InfeasiblePoseError`.
    """
    ext = renamed_keyword(external_wrench, disturbance, "external_wrench", "disturbance")
    pts = as_array(points, "points", shape=(None, 3))
    ori = np.zeros((1, 3)) if orientations is None else \
        as_array(orientations, "orientations", shape=(None, 3))
    Pn, On = pts.shape[0], ori.shape[0]
    poses = np.hstack([np.repeat(pts, On, axis=0), np.tile(ori, (Pn, 1))])
    tip = robot.has_tipping
    total = poses.shape[0] * (2 if tip else 1)
    done = 0
    res = {}
    for with_tip in ((False, True) if tip else (False,)):
        out = np.empty(poses.shape[0], dtype=bool)
        for s0 in range(0, poses.shape[0], chunk):
            sl = slice(s0, s0 + chunk)
            out[sl] = wrench_feasible(robot, poses[sl], tipping=with_tip,
                                      external_wrench=ext)
            done += out[sl].size
            if progress is not None:
                progress(done, total)
        res[with_tip] = out.reshape(Pn, On)
    feas: np.ndarray = np.asarray(res[False].all(axis=1))
    feas_t: np.ndarray | None = np.asarray(res[True].all(axis=1)) if tip else None
    if robot.desired_workspace is not None:
        lo, hi = robot.desired_workspace
        tol = BOX_REL * (1 + np.abs(robot.desired_workspace).max())
        inside = np.all((pts >= lo - tol) & (pts <= hi + tol), axis=1)
    else:
        inside = np.ones(Pn, dtype=bool)
    denom = max(int(inside.sum()), 1)
    cov = float((feas & inside).sum() / denom)
    cov_t = float((feas_t & inside).sum() / denom) if tip else None
    return WorkspaceResult(pts, ori, feas, feas_t, res[tip], shape, cov, cov_t)
