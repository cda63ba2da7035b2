"""The tallest workspace box with a verified deployment, by bisection on its height
between verified plans (:func:`taut.cdpr.plan_deployment`) and the placement-independent
lift certificate (:func:`taut.cdpr.lift_bound`). Units: m."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import MAX_CDPR_LENGTH_M, as_bounded
from ...errors import InvalidInputError
from ..statics._common import wrench_vertices
from .._tol import TALLEST_CERTIFICATE_TOL
from .moving_base import plan_moving_deployment, staged_lift_bound
from .deploy import DeploymentResult, plan_deployment
from .lift import LiftBound, lift_bound
from ..model.robot import CableRobot
from .placement import workspace_box
from ..._repr import CompactRepr

__all__ = ["TallestWorkspace", "tallest_workspace"]


@dataclass(frozen=True, repr=False)
class TallestWorkspace(CompactRepr):
    """Outcome of :func:`tallest_workspace`.

    Attributes
    ----------
    height : float
        ``zmax`` of the tallest box with a verified deployment, m (NaN if none was found).
    workspace : (2, 3) or None
        That box.
    deployment : DeploymentResult, MovingDeploymentResult (``stages > 1``) or None
        Its verified deployment (``deployment.success`` is True).
    certified_limit : float
        Lowest ``zmax`` at which :func:`lift_bound` refutes the box, m: every box reaching
        this high is proved infeasible for every placement. ``inf`` when the certificate
        does not refute even the requested ``zmax``.
    certificate : LiftBound
        The certificate at ``certified_limit`` (or at the requested ``zmax`` when it does
        not refute there).
    failed_below : float
        Lowest ``zmax`` at which the planner found no placement, m (NaN if none): the true
        tallest height lies between ``height`` and ``certified_limit``, most likely below
        this (the optimiser is not exhaustive).
    tried : tuple of (float, bool)
        ``(zmax, verified feasible)`` of every :func:`plan_deployment` call, in order.
    """

    height: float
    workspace: np.ndarray | None
    deployment: DeploymentResult | None
    certified_limit: float
    certificate: LiftBound
    failed_below: float
    tried: tuple[tuple[float, bool], ...]

    @property
    def success(self) -> bool:
        """True when some box has a verified deployment."""
        return self.deployment is not None

    @property
    def status(self) -> str:
        """``"ok"``, or ``"budget_exhausted"`` when the planner verified no box (the seeded
        search is no proof either way)."""
        return "ok" if self.success else "budget_exhausted"

    @property
    def message(self) -> str:
        """One line with the bracket of the tallest height."""
        top = (f"certified limit {self.certified_limit:.4g} m" if np.isfinite(
            self.certified_limit) else "no certified limit")
        if self.success:
            return f"verified up to zmax = {self.height:.4g} m; {top}"
        return f"no verified deployment; {top}"


def tallest_workspace(robot: CableRobot, workspace: ArrayLike, *,
                      external_wrench: ArrayLike | None = None,
                      tol: float = 0.05, certificate_tol: float = TALLEST_CERTIFICATE_TOL,
                      samples: Sequence[int] = (41, 5), warm_start: bool = True,
                      stages: int = 1,
                      **plan_options: Any) -> TallestWorkspace:
    """Tallest box with a verified deployment, by bisection on ``zmax``.

    Parameters
    ----------
    robot : CableRobot
    workspace : (2, 3) or (6,)
        Box whose x/y extent and ``zmin`` are kept; its ``zmax`` is the highest height
        tried.
    external_wrench : (V, n), optional
        As for :func:`plan_deployment` (also used by the certificate).
    tol : float
        Stop when the bracket ``[verified, failed]`` of ``zmax`` is narrower, m.
    certificate_tol : float
        Resolution of the certified limit, m.
    samples : (2,) ints
        Top-face grid of the certificate (:func:`lift_bound`).
    warm_start : bool
        Centre each search on the last verified placement (the previous box is a slice of
        the taller one, so that placement is a good start).
    stages : int
        1: one fixed placement (:func:`plan_deployment`). More: the active base moves
        during the task, one placement per slice of the box along x
        (:func:`taut.cdpr.deployment.moving_base.plan_moving_deployment`, whose per-slice
        certificate :func:`taut.cdpr.deployment.moving_base.staged_lift_bound` then replaces
        :func:`lift_bound`); ``deployment`` is then a ``MovingDeploymentResult``.
    **plan_options
        Passed to :func:`plan_deployment` (``required_twist``, ``grid``, ``maxiter``, ...).

    Returns
    -------
    TallestWorkspace

    Notes
    -----
    1. The certificate's bound decreases as ``zmax`` rises (the exits get closer above
       the attachment points), so bisection on :func:`lift_bound` gives the certified limit
       ``z_c``: at ``z_c`` no placement exists, nor for any taller box (it contains the
       refuted slice).
    2. ``plan_deployment`` is bisected on ``zmax`` in ``(zmin, min(zmax, z_c))``: a
       verified answer raises the lower end, a failure lowers the upper end. The requested
       ``zmax`` is tried first when the certificate does not refute it. Each call costs one
       planner run (about ``log2(height range / tol)`` calls).

    The planner is a seeded heuristic: a failure does not prove infeasibility, so the
    returned height is a verified lower bound of the true tallest height and
    ``certified_limit`` a proved upper bound.
    """
    box = workspace_box(workspace)
    if not (isinstance(stages, (int, np.integer)) and 1 <= stages <= 50):
        raise InvalidInputError("stages", "must be an integer from 1 to 50")
    tol = as_bounded(tol, "tol", MAX_CDPR_LENGTH_M, "m")
    certificate_tol = as_bounded(certificate_tol, "certificate_tol", MAX_CDPR_LENGTH_M, "m")
    D = None if external_wrench is None else wrench_vertices(robot, external_wrench)
    zmin, ztop = float(box[0, 2]), float(box[1, 2])

    def at(z: float) -> np.ndarray:
        b = box.copy()
        b[1, 2] = z
        return b

    def certify(z: float) -> LiftBound:
        if stages > 1:
            return staged_lift_bound(robot, at(z), stages, external_wrench=D,
                                     samples=samples)
        return lift_bound(robot, at(z), external_wrench=D, samples=samples)

    def plan(start: CableRobot, z: float) -> Any:
        if stages > 1:
            return plan_moving_deployment(start, at(z), stages=stages, external_wrench=D,
                                          **plan_options)
        return plan_deployment(start, at(z), external_wrench=D, **plan_options)

    cert = certify(ztop)
    limit = np.inf
    if cert.refutes:
        lo, hi, hi_cert = zmin, ztop, cert        # lo: not refuted (or the floor)
        while hi - lo > certificate_tol:
            mid = 0.5 * (lo + hi)
            c = certify(mid)
            if c.refutes:
                hi, hi_cert = mid, c
            else:
                lo = mid
        limit, cert = hi, hi_cert
    best: Any = None
    height = np.nan
    tried: list[tuple[float, bool]] = []
    start = robot
    lo = zmin                                    # no verified box yet
    hi = min(ztop, limit)                        # infeasible when refuted
    z = ztop if not cert.refutes else 0.5 * (lo + hi)
    while True:
        res = plan(start, z)
        tried.append((z, bool(res.success)))
        if res.success:
            best, height, lo = res, z, z
            if warm_start:
                start = res.robot
            if z >= hi:                          # the requested box itself
                hi = z
        else:
            hi = z
        if hi - lo <= tol:
            break
        z = 0.5 * (lo + hi)
    fails = [zz for zz, ok in tried if not ok]
    return TallestWorkspace(height, None if best is None else at(height), best, limit, cert,
                            min(fails) if fails else np.nan, tuple(tried))
