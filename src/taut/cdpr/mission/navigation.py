"""Navigation mode (issue 30 part 2; FASTKIT §2.3): the coupled bases, platform locked and
cables still, drive as ONE rigid footprint (:func:`~taut.cdpr.mission.warehouse.coupled_footprint`)
from one pose to another on the warehouse floor.

One search, two users: the route is found by the sheet planner's SE(2) lattice A*
(:mod:`taut.plan.se2._lattice` / :mod:`taut.plan._kernels.lattice`, through its
footprint-agnostic core :mod:`taut.plan.se2.rigid`): the footprint's corners (grown by the
warehouse's ``clearance``) are the "robots", their convex hull the body, the floor the free
space and the shelves blocked obstacles. Every lattice move is *proved* valid by
conservative advancement on the compiled clearance (every pose of the continuous motion,
not samples). The route is then timed under the speed, acceleration and turning-rate
limits (a trapezoidal profile along each straight SE(2) segment, stopping at every
corner) and *verified independently*: the timed motion is resampled finer and every
sample's footprint is checked with shapely (inside the floor with the clearance, clear of
every shelf by the clearance), and every interval between samples is covered by the
1-Lipschitz bound of :mod:`taut.plan.checks._geometry` (no corner moves farther between
two samples than the two samples' slacks add up to).

The result types live with the engine (:mod:`taut.cdpr.mission._navigate`) and are
exported here and from :mod:`taut.cdpr`.

Refusals carry what is proven: the start or goal footprint collides (a proof: the pose
itself is invalid, named shelf or wall), or the lattice holds no route (a proof at the
lattice's resolution only: no route exists whose every pose keeps about a lattice spacing
of corner motion to spare; a tighter route is not ruled out), or the search's budget ran
out (nothing proven).
"""

from __future__ import annotations

from typing import Any

from ..._validate import MAX_SPEED, as_array, as_bounded, as_count, require_instance
from ._navigate import NavigationCertificate, NavigationResult, navigate
from .warehouse import Warehouse

__all__ = ["NavigationCertificate", "NavigationResult", "plan_navigation"]


def plan_navigation(warehouse: Warehouse, start: Any, goal: Any, *,
                    max_speed: float | None = None, max_accel: float | None = None,
                    max_turn_rate: float | None = None, spacing: float = 0.25,
                    expansions: int = 3_000_000, sample_time: float = 0.1
                    ) -> NavigationResult:
    """Plan the coupled bases from ``start`` to ``goal`` (module docstring).

    Parameters
    ----------
    warehouse : Warehouse
    start, goal : array_like (3,)
        ``(x, y, yaw)`` of the coupled bases, m and rad.
    max_speed : float, optional
        m/s (default: the warehouse's ``max_speed``).
    max_accel : float, optional
        m/s^2 (default: the warehouse's ``max_accel``).
    max_turn_rate : float, optional
        rad/s (default: the warehouse's ``max_turn_rate``).
    spacing : float, default 0.25
        Lattice spacing, m (coarser when the floor would need too many nodes; reported).
    expansions : int, default 3 000 000
        Most lattice nodes expanded (the deterministic budget).
    sample_time : float, default 0.1
        Time between the returned samples, s.

    Returns
    -------
    NavigationResult

    Examples
    --------
    >>> from taut.io.warehouse import load_warehouse
    >>> wh = load_warehouse("examples/cdpr/warehouse.yaml")   # doctest: +SKIP
    >>> plan_navigation(wh, wh.start, [5.0, 2.0, 0.0]).success   # doctest: +SKIP
    True
    """
    require_instance(warehouse, Warehouse, "warehouse")
    a = as_array(start, "start", shape=(3,))
    b = as_array(goal, "goal", shape=(3,))
    limits = (
        as_bounded(warehouse.max_speed if max_speed is None else max_speed, "max_speed",
                   MAX_SPEED, "m/s"),
        as_bounded(warehouse.max_accel if max_accel is None else max_accel, "max_accel",
                   MAX_SPEED, "m/s^2"),
        as_bounded(warehouse.max_turn_rate if max_turn_rate is None else max_turn_rate,
                   "max_turn_rate", MAX_SPEED, "rad/s"))
    h = as_bounded(spacing, "spacing", 10.0, "m")
    n = as_count(expansions, "expansions", minimum=1, maximum=100_000_000)
    dt = as_bounded(sample_time, "sample_time", 10.0, "s")
    return navigate(warehouse, a, b, limits, h, n, dt)
