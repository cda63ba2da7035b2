"""Wrench-feasible workspace (WFW, FASTKIT §4) over grids of platform positions, with and
without the tipping constraints of mobile bases, for one orientation or a sweep of them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import MAX_WORKSPACE_POSES, as_array
from ...errors import InvalidInputError
from .._tol import BOX_REL, CLOSURE_TOL
from .closure import closure_pass, inside_pass
from ..model.robot import CableRobot
from ..sets.wrench import wrench_feasible
from ..._validate import as_count, require_instance
from ..._repr import CompactRepr

__all__ = ["WorkspaceResult", "grid_points", "wrench_feasible_workspace"]


def grid_points(box: ArrayLike, shape: ArrayLike) -> tuple[np.ndarray, tuple[int, int, int]]:
    """Regular grid over ``box`` ([[xmin, ymin, zmin], [xmax, ymax, zmax]], m) with ``shape``
    (nx, ny, nz) points per axis (a flat axis gets one point). Returns points (P, 3) in
    C order (x slowest) and the effective shape."""
    b = as_array(box, "box", shape=(2, 3))
    if isinstance(shape, (str, bytes)):
        raise InvalidInputError("grid", "must be three positive integers nx ny nz")
    sh = as_array(shape, "grid")
    if sh.shape != (3,) or np.any(sh < 1) or np.any(sh != np.round(sh)):
        raise InvalidInputError("grid", "must be three positive integers nx ny nz")
    if float(np.prod(sh)) > MAX_WORKSPACE_POSES:
        raise InvalidInputError("grid", f"{' x '.join(f'{n:g}' for n in sh)} points exceeds "
                                        f"{MAX_WORKSPACE_POSES:,} workspace poses")
    nx, ny, nz = (int(n) if b[1, k] > b[0, k] else 1 for k, n in enumerate(sh))
    eff = (nx, ny, nz)
    axes = [np.linspace(b[0, k], b[1, k], eff[k]) if eff[k] > 1 else
            np.array([0.5 * (b[0, k] + b[1, k])]) for k in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]), eff


@dataclass(frozen=True, repr=False)
class WorkspaceResult(CompactRepr):
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
    feasible_sliding : (P,) bool or None
        Also without sliding a mobile base (tension limits, tipping and the friction
        condition of :mod:`taut.cdpr.statics.sliding`); None when no base has a friction
        coefficient.
    coverage_sliding : float or None
        Coverage with all three conditions.
    binding : (P,) str
        Per position, the first condition (in the order ``"limits"``, ``"tipping"``,
        ``"sliding"``, ``"exits_box"``) whose addition makes it infeasible; ``""`` where
        feasible with every condition the model has.
    closure : (P,) bool or None
        Wrench closure (positive tensions balance every wrench, no tension limits) at
        every orientation; None unless asked for (``closure=True``).
    coverage_closure : float or None
        Fraction of positions (in the desired workspace) with wrench closure.
    inside_exits : (P,) bool or None
        The whole platform inside the exits' bounding box at every orientation
        (:func:`taut.cdpr.workspace.exit_box.platform_inside_exits`); None unless the model has
        ``platform_inside_exits``.
    coverage_inside : float or None
        Coverage with every condition of the model and the exits' box.
    """

    points: np.ndarray
    orientations: np.ndarray
    feasible: np.ndarray
    feasible_tipping: np.ndarray | None
    per_orientation: np.ndarray
    shape: tuple[int, ...] | None
    coverage: float
    coverage_tipping: float | None
    feasible_sliding: np.ndarray | None = None
    coverage_sliding: float | None = None
    binding: np.ndarray | None = None
    closure: np.ndarray | None = None
    coverage_closure: float | None = None
    inside_exits: np.ndarray | None = None
    coverage_inside: float | None = None


def wrench_feasible_workspace(robot: CableRobot, points: ArrayLike, *,
                              orientations: ArrayLike | None = None,
                              external_wrench: ArrayLike | None = None,
                              shape: tuple[int, ...] | None = None, chunk: int = 2048,
                              progress: Callable[[int, int], None] | None = None,
                              closure: bool = False,
                              closure_tol: float = CLOSURE_TOL) -> WorkspaceResult:
    """Evaluate the wrench-feasible workspace at positions ``points`` (P, 3), m.

    A position belongs to the WFW when, at every orientation of ``orientations`` ((O, 3)
    roll-pitch-yaw, rad; default level), the cables can hold platform and payload weight
    plus every wrench of ``external_wrench`` ((V, n), N and N m) within their tension
    limits, and, for ``feasible_tipping``, without tipping a mobile base. Vectorised (see
    :func:`taut.cdpr.sets.wrench.wrench_feasible`). ``progress(done, total)`` is called after
    each block of ``chunk`` poses. Positions outside the frame raise :class:`InfeasiblePoseError`.

    With ``closure=True`` the result also holds the wrench-closure workspace (exact test
    per pose, positivity only, :mod:`taut.cdpr.workspace.closure`; ``closure_tol`` as for
    :func:`taut.cdpr.wrench_closure`). When the model has ``platform_inside_exits``, the
    platform staying inside the exits' bounding box is a fourth condition
    (``inside_exits``, binding ``"exits_box"``).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> fc = load_cdpr_model("fastkit_fc")
    >>> ws = wrench_feasible_workspace(fc, [[0, 0, 1.2], [-1.5, 0, 0.2]], closure=True)
    >>> ws.feasible.tolist(), ws.closure.tolist()    # with gravity neither contains the other
    ([False, True], [True, False])
    """
    require_instance(robot, CableRobot, "robot")
    if not isinstance(closure, (bool, np.bool_)):
        raise InvalidInputError("closure", f"must be true or false, got {closure!r}")
    chunk = as_count(chunk, "chunk", minimum=1)
    pts = as_array(points, "points", shape=(None, 3))
    ori = np.zeros((1, 3)) if orientations is None else \
        as_array(orientations, "orientations", shape=(None, 3))
    Pn, On = pts.shape[0], ori.shape[0]
    if Pn * On > MAX_WORKSPACE_POSES:
        raise InvalidInputError("orientations" if On > 1 else "points",
                                f"{Pn:,} points x {On} orientations exceeds "
                                f"{MAX_WORKSPACE_POSES:,} workspace poses")
    poses = np.hstack([np.repeat(pts, On, axis=0), np.tile(ori, (Pn, 1))])
    passes = [("limits", False, False)]
    if robot.has_tipping:
        passes.append(("tipping", True, False))
    if robot.has_sliding:
        passes.append(("sliding", True, True))
    extra = int(closure) + int(robot.platform_inside_exits)
    counter = _Progress(progress, poses.shape[0] * (len(passes) + extra))
    res = {name: _feasible_pass(robot, poses, tip, slide, external_wrench, chunk,
                                counter).reshape(Pn, On)
           for name, tip, slide in passes}
    feas = {name: np.asarray(r.all(axis=1)) for name, r in res.items()}
    if robot.platform_inside_exits:
        feas["exits_box"] = np.asarray(inside_pass(robot, poses, counter).reshape(Pn, On)
                                       .all(axis=1))
    inside = _inside_desired(robot, pts)
    denom = max(int(inside.sum()), 1)
    binding = np.full(Pn, "", dtype="<U9")
    so_far = np.ones(Pn, dtype=bool)
    cov: dict[str, float] = {}
    for name, f in feas.items():               # the first condition that fails binds
        binding[so_far & ~f] = name
        so_far &= f
        # limits, tipping and sliding are nested passes; the exits' box adds to all of them
        cov[name] = float(((so_far if name == "exits_box" else f) & inside).sum() / denom)
    wc = None if not closure else np.asarray(closure_pass(
        robot, poses, closure_tol, chunk, counter).reshape(Pn, On).all(axis=1))
    last = "tipping" if "tipping" in res else "limits"
    return WorkspaceResult(pts, ori, feas["limits"], feas.get("tipping"), res[last], shape,
                           cov["limits"], cov.get("tipping"), feas.get("sliding"),
                           cov.get("sliding"), binding, wc,
                           None if wc is None else float((wc & inside).sum() / denom),
                           feas.get("exits_box"), cov.get("exits_box"))


class _Progress:
    """Calls ``progress(done, total)`` as blocks of poses finish."""

    def __init__(self, progress: Callable[[int, int], None] | None, total: int) -> None:
        self.progress, self.total, self.done = progress, total, 0

    def step(self, n: int) -> None:
        self.done += n
        if self.progress is not None:
            self.progress(self.done, self.total)


def _feasible_pass(robot: CableRobot, poses: np.ndarray, tipping: bool, sliding: bool,
                   ext: ArrayLike | None, chunk: int, counter: _Progress) -> np.ndarray:
    out = np.empty(poses.shape[0], dtype=bool)
    for s0 in range(0, poses.shape[0], chunk):
        sl = slice(s0, s0 + chunk)
        out[sl] = wrench_feasible(robot, poses[sl], tipping=tipping, sliding=sliding,
                                  external_wrench=ext)
        counter.step(out[sl].size)
    return out


def _inside_desired(robot: CableRobot, pts: np.ndarray) -> np.ndarray:
    if robot.desired_workspace is None:
        return np.ones(pts.shape[0], dtype=bool)
    lo, hi = robot.desired_workspace
    tol = BOX_REL * (1 + np.abs(robot.desired_workspace).max())
    return np.all((pts >= lo - tol) & (pts <= hi + tol), axis=1)
