"""Wrench-closure workspace (WCW) and the exits'-box condition over grids of poses: the
per-pose passes that :func:`taut.cdpr.wrench_feasible_workspace` runs when asked for
``closure=True`` or when the model says ``platform_inside_exits`` (private helpers; the
public front end is the workspace function).

The wrench-closure test per pose is exact (:func:`taut.cdpr.wrench_closure`: rank of the
wrench matrix ``W`` (FASTKIT eq. 18) and Gordan's alternative as one HiGHS LP), with no
tension limits, only positivity ``t > 0``. A position is in the WCW when it has closure at
every swept orientation.

Relation to the wrench-feasible workspace (WFW): if, at a pose, every wrench of a set
containing a neighbourhood of the origin can be balanced with tensions ``t >= 0``, the
cone spanned by the columns of ``W`` contains that neighbourhood, hence is all of R^n:
the pose has wrench closure. So WCW ⊇ WFW for any required wrench set with the origin in
its interior (in particular without gravity and with an external-wrench box around zero,
or without gravity and ``t_min > 0``). With gravity the inclusion fails for suspended
robots, which hold their weight without closure.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..sets.closure import wrench_closure
from .exit_box import platform_inside_exits
from ..model.robot import CableRobot

__all__: list[str] = []


def closure_pass(robot: CableRobot, poses: np.ndarray, closure_tol: float, chunk: int,
                 counter: Any) -> np.ndarray:
    """Wrench closure at validated poses (B, 6), block by block -> (B,) bool;
    ``counter.step(n)`` after each block of ``chunk`` poses."""
    out = np.empty(poses.shape[0], dtype=bool)
    for s0 in range(0, poses.shape[0], chunk):
        sl = slice(s0, s0 + chunk)
        out[sl] = wrench_closure(robot, poses[sl], closure_tol=closure_tol)
        counter.step(out[sl].size)
    return out


def inside_pass(robot: CableRobot, poses: np.ndarray, counter: Any) -> np.ndarray:
    """Platform inside the exits' box at poses (B, 6) -> (B,) bool (cheap: one block)."""
    out = np.asarray(platform_inside_exits(robot, poses), dtype=bool)    # poses are (B, 6)
    counter.step(out.size)
    return out
