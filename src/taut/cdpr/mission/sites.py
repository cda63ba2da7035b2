"""Where to stand (issue 30 part 3): deployment sites of the coupled bases that serve the
warehouse's tasks.

A *site* is a pose ``(x, y, yaw)`` of the coupled bases (the model's relative placement of
the bases, as they navigate) with the stabilisers deployed. It *serves* a task when, for
both the pick and the place of the task (:func:`~taut.cdpr.mission.warehouse.to_robot_frame`):

* the gripper reaches it across the cable plane: ``|q_y| <= gripper_reach``;
* the platform target ``(q_x, 0, q_z)`` is inside the robot's frame bounds and wrench
  feasible with tipping and sliding (:func:`taut.cdpr.wrench_feasible` on the deployed
  robot with the warehouse's friction) both empty (arriving to pick, leaving after the
  place) and carrying the task's mass (leaving the pick, arriving to place);

and the deployed footprint (:func:`~taut.cdpr.mission.warehouse.coupled_footprint` with
the stabilisers) is inside the floor and keeps ``clearance`` from every wall and shelf.

Candidates: the bases park parallel to a shelf face (docs/mission.md). For every edge of
every shelf, candidate poses run along the face, ``standoff`` from it, every ``step``
metres, with the shelf on either side of the plane as the edge's outward normal says;
candidates whose footprint collides are dropped. Each candidate's served set is computed
once; then a **greedy set cover** picks the candidate serving the most unserved tasks
(ties: among the 8 most central candidates, those whose targets spread least along the
cable plane, the larger least capacity margin, then the nearer to the start), until no
candidate serves a new task. Greedy cover is within ``ln(n) + 1`` of the fewest sites
(it is not guaranteed to be the fewest). Tasks no candidate serves are reported with the
reason of the candidate that came closest (the result types live with the engine,
:mod:`taut.cdpr.mission._cover`, and are exported here and from :mod:`taut.cdpr`) (in reach but not wrench feasible, or out of
every gripper's reach), and the rest goes on.
"""

from __future__ import annotations

from ..._validate import MAX_CDPR_LENGTH_M, as_bounded, require_instance
from ._cover import Site, SitesResult, UnservedTask, cover_sites
from .warehouse import Warehouse

__all__ = ["Site", "UnservedTask", "SitesResult", "choose_sites"]


def choose_sites(warehouse: Warehouse, *, step: float = 0.25) -> SitesResult:
    """Deployment sites serving the warehouse's tasks (module docstring).

    Parameters
    ----------
    warehouse : Warehouse
    step : float, default 0.25
        Spacing of the candidate poses along each shelf face, m.

    Returns
    -------
    SitesResult

    Examples
    --------
    >>> from taut.io.warehouse import load_warehouse
    >>> res = choose_sites(load_warehouse("examples/cdpr/warehouse.yaml"))  # doctest: +SKIP
    >>> len(res.sites), [u.name for u in res.unserved]                      # doctest: +SKIP
    (2, ['box9'])
    """
    require_instance(warehouse, Warehouse, "warehouse")
    h = as_bounded(step, "step", MAX_CDPR_LENGTH_M, "m")
    return cover_sites(warehouse, h)
