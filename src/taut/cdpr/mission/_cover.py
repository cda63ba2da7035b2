"""Engine of :func:`taut.cdpr.mission.sites.choose_sites` (private): candidate poses along
the shelf faces, the tasks each serves, and the greedy set cover."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..._outcome import check_status
from ..model.parts import Payload
from ..model.robot import CableRobot, with_friction, with_stabilisers
from ..sets.wrench import capacity_margin, wrench_feasible
from .._tol import NAV_TOL
from ._navigate import footprint_slack
from .warehouse import Warehouse, coupled_footprint

__all__ = ["Site", "UnservedTask", "SitesResult", "cover_sites", "deployed_robot",
           "with_payload"]


@dataclass(frozen=True, eq=False)
class Site:
    """One deployment of the coupled bases.

    Attributes
    ----------
    pose : ndarray (3,)
        ``(x, y, yaw)`` of the coupled bases in the world, m and rad.
    robot : CableRobot
        The deployed robot the statics use, in the robot frame (stabilisers deployed,
        the warehouse's friction on the bases; bases at the model's placement).
    stabilisers_deployed : bool
    base_poses : ndarray (n_mobile, 3)
        World ``(x, y, theta)`` of each mobile base, m and rad, in the model's base order.
    task_names : tuple of str
        Tasks done at this site, in the warehouse's order.
    picks, places : ndarray (k, 3)
        Platform targets of those tasks in the robot frame, m (``y = 0``: the cable plane).
    margin : float
        Least capacity margin (:func:`taut.cdpr.capacity_margin`, tipping on) over the
        targets, empty and loaded, N (>= 0).
    shelf : str
        The shelf whose face the bases park along.
    """

    pose: np.ndarray
    robot: CableRobot
    stabilisers_deployed: bool
    base_poses: np.ndarray
    task_names: tuple[str, ...]
    picks: np.ndarray
    places: np.ndarray
    margin: float
    shelf: str


@dataclass(frozen=True)
class UnservedTask:
    """A task no candidate site serves, and why (one line)."""

    name: str
    reason: str


@dataclass(frozen=True, eq=False)
class SitesResult:
    """Outcome of :func:`choose_sites`.

    Attributes
    ----------
    success : bool
        Every task is served.
    status : str
        ``"ok"``, or ``"unreachable"`` when some tasks are not served (``sites`` still
        serve the others: the mission goes on).
    message : str
    sites : tuple of Site
        In the order the greedy cover chose them.
    unserved : tuple of UnservedTask
    candidates : int
        Collision-free candidate poses evaluated.
    """

    success: bool
    status: str
    message: str
    sites: tuple[Site, ...]
    unserved: tuple[UnservedTask, ...]
    candidates: int = 0

    def __post_init__(self) -> None:
        check_status(self.status)


#: How far (m) candidate poses run past each end of a shelf face: half the FASTKIT
#: workspace's 5 m length, so a box at a face's end can sit mid-workspace.
_BEYOND = 2.5

#: Tied candidates (serving equally many new tasks) whose capacity margins are compared:
#: the most central ones (smallest spread of their targets along the cable plane); the
#: margin's cost (~0.3 s a candidate here) bounds it.
_TIES = 8


def deployed_robot(warehouse: Warehouse) -> CableRobot:
    """The robot as it works at a site: stabilisers deployed, the warehouse's friction."""
    robot = with_stabilisers(warehouse.robot, deployed=True)
    return robot if warehouse.friction is None else with_friction(robot, warehouse.friction)


def with_payload(robot: CableRobot, mass: float) -> CableRobot:
    """The robot carrying ``mass`` kg at the payload's centre of mass (0: empty gripper)."""
    p = robot.payload
    scale = mass / p.mass if p.mass > 0 else 0.0
    return replace(robot, payload=Payload(mass, p.com, p.inertia * scale))


def _candidates(warehouse: Warehouse, step: float) -> tuple[np.ndarray, list[str]]:
    """Poses (K, 3) parallel to every shelf face at ``standoff`` from it, both headings,
    and the shelf of each."""
    poses, names = [], []
    for sh in warehouse.shelves:
        v = np.asarray(sh.footprint.exterior.coords)          # counter-clockwise, closed
        for a, b in zip(v[:-1], v[1:]):
            e = b - a
            length = float(np.linalg.norm(e))
            u = e / length
            out = np.array([u[1], -u[0]])                     # outward normal
            s = np.arange(-_BEYOND, length + _BEYOND + 1e-9, step)
            xy = a + s[:, None] * u + warehouse.standoff * out
            yaw = float(np.arctan2(u[1], u[0]))
            for turn in (0.0, np.pi):
                psi = np.angle(np.exp(1j * (yaw + turn)))
                poses.append(np.column_stack([xy, np.full(len(s), psi)]))
                names += [sh.name] * len(s)
    return (np.vstack(poses) if poses else np.zeros((0, 3))), names


def _targets(warehouse: Warehouse, poses: np.ndarray, point: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """Platform targets (K, 3) of a world point seen from each pose, and whether the
    gripper reaches it across the cable plane."""
    d = np.asarray(point, float)[None, :2] - poses[:, :2]
    c, sn = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    q = np.column_stack([c * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + c * d[:, 1],
                         np.full(len(poses), float(point[2]))])    # R(-yaw) (p - xy)
    reach = np.abs(q[:, 1]) <= warehouse.gripper_reach + NAV_TOL
    return np.column_stack([q[:, 0], np.zeros(len(q)), q[:, 2]]), reach


def _feasible(robot: CableRobot, targets: np.ndarray, masses: tuple[float, ...]
              ) -> np.ndarray:
    """(K,) targets inside the frame box and wrench feasible (tipping, sliding) with
    every payload mass of ``masses``."""
    lo, hi = robot.bounds
    ok = np.all((targets >= lo - NAV_TOL) & (targets <= hi + NAV_TOL), axis=1)
    for m in masses:
        if ok.any():
            poses = np.column_stack([targets[ok], np.zeros((int(ok.sum()), 3))])
            ok[ok] = wrench_feasible(with_payload(robot, m), poses, tipping=True,
                                     sliding=True)
    return ok


def _served(warehouse: Warehouse, robot: CableRobot, poses: np.ndarray
            ) -> tuple[np.ndarray, list[str]]:
    """(K, n_tasks) which candidate serves which task, and a reason per task for the
    tasks no candidate serves."""
    n = len(warehouse.tasks)
    served = np.zeros((len(poses), n), dtype=bool)
    reasons = []
    for j, t in enumerate(warehouse.tasks):
        tp, rp = _targets(warehouse, poses, t.pick)
        tq, rq = _targets(warehouse, poses, t.place)
        both = rp & rq
        ok = both.copy()
        if ok.any():
            ok[ok] = _feasible(robot, tp[ok], (0.0, t.mass))
        if ok.any():
            ok[ok] = _feasible(robot, tq[ok], (t.mass, 0.0))
        served[:, j] = ok
        if ok.any():
            reasons.append("")
        elif not rp.any():
            reasons.append(f"the pick ({_xyz(t.pick)}) m is beyond the gripper's reach "
                           f"({warehouse.gripper_reach:g} m across the cable plane) from every "
                           "collision-free site along a shelf face")
        elif not rq.any():
            reasons.append(f"the place ({_xyz(t.place)}) m is beyond the gripper's reach "
                           f"({warehouse.gripper_reach:g} m) from every collision-free site")
        elif not both.any():
            reasons.append("no collision-free site reaches both its pick and its place")
        else:
            pick_ok = _feasible(robot, tp[both], (0.0, t.mass))
            where = ("pick" if not pick_ok.any() else "place")
            pt = t.pick if where == "pick" else t.place
            reasons.append(f"out of reach: at every one of the {int(both.sum())} sites "
                           f"reaching it, the cables cannot hold the platform with the "
                           f"{t.mass:g} kg box at the {where} ({_xyz(pt)}) m within tension "
                           "limits without tipping or sliding a base")
    return served, reasons


def _xyz(p: np.ndarray) -> str:
    return ", ".join(f"{v:.3g}" for v in p)


def _site(warehouse: Warehouse, robot: CableRobot, pose: np.ndarray, tasks: list[int],
          shelf: str) -> Site:
    picks = np.stack([_targets(warehouse, pose[None], warehouse.tasks[j].pick)[0][0]
                      for j in tasks])
    places = np.stack([_targets(warehouse, pose[None], warehouse.tasks[j].place)[0][0]
                       for j in tasks])
    margin = np.inf
    for j, p, q in zip(tasks, picks, places):
        pts = np.column_stack([np.stack([p, q]), np.zeros((2, 3))])
        for m in (0.0, warehouse.tasks[j].mass):
            margin = min(margin, float(capacity_margin(with_payload(robot, m), pts).min()))
    c, s = np.cos(pose[2]), np.sin(pose[2])
    bases = np.array([[pose[0] + c * b.pose[0] - s * b.pose[1],
                       pose[1] + s * b.pose[0] + c * b.pose[1],
                       float(np.angle(np.exp(1j * (b.pose[2] + pose[2]))))]
                      for b in robot.bases if b.mobile])
    return Site(pose.copy(), robot, True, bases,
                tuple(warehouse.tasks[j].name for j in tasks), picks, places, margin, shelf)


def _spread(warehouse: Warehouse, poses: np.ndarray, new: np.ndarray) -> np.ndarray:
    """Largest ``|q_x|`` (m) of the targets of the tasks ``new`` (K, n bool) seen from
    each candidate: how far from the middle of the cable plane its work lies."""
    out = np.zeros(len(poses))
    for j, t in enumerate(warehouse.tasks):
        for pt in (t.pick, t.place):
            tg, _ = _targets(warehouse, poses, pt)
            out = np.where(new[:, j], np.maximum(out, np.abs(tg[:, 0])), out)
    return out


def _margins(warehouse: Warehouse, robot: CableRobot, poses: np.ndarray, new: np.ndarray
             ) -> np.ndarray:
    """Least capacity margin (N) over the tasks ``new`` (K, n bool) of each candidate."""
    out = np.full(len(poses), np.inf)
    for j, t in enumerate(warehouse.tasks):
        k = np.flatnonzero(new[:, j])
        if not len(k):
            continue
        for pt, order in ((t.pick, (0.0, t.mass)), (t.place, (t.mass, 0.0))):
            tg, _ = _targets(warehouse, poses[k], pt)
            P = np.column_stack([tg, np.zeros((len(k), 3))])
            for m in order:
                out[k] = np.minimum(out[k], capacity_margin(with_payload(robot, m), P))
    return out


def cover_sites(warehouse: Warehouse, step: float) -> SitesResult:
    """:func:`~taut.cdpr.mission.sites.choose_sites` on validated inputs."""
    robot = deployed_robot(warehouse)
    body = coupled_footprint(robot, deployed=True)
    poses, shelf = _candidates(warehouse, step)
    if len(poses):
        gap, _ = footprint_slack(warehouse, body, poses)
        keep = gap >= warehouse.clearance - NAV_TOL
        poses, shelf = poses[keep], [s for s, k in zip(shelf, keep) if k]
    served, reasons = _served(warehouse, robot, poses)
    todo = np.asarray(served.any(axis=0), dtype=bool)
    sites: list[Site] = []
    while todo.any():
        new = served & todo[None, :]
        count = new.sum(axis=1)
        best = np.flatnonzero(count == count.max())
        best = best[np.argsort(_spread(warehouse, poses[best], new[best]),
                               kind="stable")[:_TIES]]
        margin = _margins(warehouse, robot, poses[best], new[best])
        dist = np.linalg.norm(poses[best, :2] - warehouse.start[:2], axis=1)
        k = int(best[np.lexsort((dist, -margin))[0]])
        sites.append(_site(warehouse, robot, poses[k], list(np.flatnonzero(new[k])),
                           shelf[k]))
        todo &= ~served[k]
    unserved = tuple(UnservedTask(t.name, r) for t, r in zip(warehouse.tasks, reasons) if r)
    n_ok = len(warehouse.tasks) - len(unserved)
    msg = (f"{len(sites)} site(s) serve {n_ok} of {len(warehouse.tasks)} tasks "
           f"(greedy set cover over {len(poses)} collision-free candidates)")
    if unserved:
        msg += "; not served: " + "; ".join(f"{u.name}: {u.reason}" for u in unserved)
    return SitesResult(not unserved, "ok" if not unserved else "unreachable", msg,
                       tuple(sites), unserved, len(poses))
