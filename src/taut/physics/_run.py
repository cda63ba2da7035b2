"""Driving a compiled sheet model through its phases: ramp, settle, release."""

from __future__ import annotations

import numpy as np

from .._units import GRAVITY
from . import _tol
from ._sheet_model import SheetSim
from ._statics import least_pull, lowest_point_load
from ._surface import surface_below

__all__ = ["ramp", "settle_phase", "ball_position", "node_positions", "release",
           "object_on_sheet", "left_sheet", "sliding_force"]


def ball_position(sim: SheetSim) -> np.ndarray:
    """Ball centre, shape (3,), simulation metres (as of the last kinematics pass, like
    :func:`node_positions`)."""
    return np.array(sim.data.xpos[sim.ball_body])


def node_positions(sim: SheetSim) -> np.ndarray:
    """Every node's position (M, 3), simulation metres."""
    return np.array(sim.data.xpos[sim.node_body])


def ramp(sim: SheetSim) -> None:
    """Move the corners from the flat copy to the robots with gravity and contacts off,
    then put an untied ball just above the sheet under it (:func:`_above_sheet`).

    Contacts are off while the sheet moves into place: a contact node kept under a held
    ball (``pin_contact``) can be dragged tens of millimetres across the flat sheet, which
    folds it, and a fold sweeping under a small ball pushed it through the sheet (seen
    next to a corner, 70 mm from a robot with 50 mm spacing)."""
    import mujoco

    m, d = sim.model, sim.data
    m.opt.gravity[:] = 0.0
    flags = int(m.opt.disableflags)
    m.opt.disableflags = flags | int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    steps = max(1, int(round(_tol.RAMP_TIME / m.opt.timestep)))
    for k in range(1, steps + 1):
        s = k / steps
        s = s * s * (3 - 2 * s)            # smooth start and stop
        d.mocap_pos[sim.corner_mocap] = (1 - s) * sim.corner_start + s * sim.corner_goal
        mujoco.mj_step(m, d)
    m.opt.disableflags = flags
    if sim.tie < 0:
        _above_sheet(sim)
    m.opt.gravity[:] = (0.0, 0.0, -GRAVITY)


def _above_sheet(sim: SheetSim) -> None:
    """Raise the ball (never lower it) so its centre is two contact offsets (ball plus
    sheet collision radius, ``ball_offset``) above every node within a mesh spacing of it
    horizontally, as on the flat start; it is left at rest."""
    import mujoco

    nodes = node_positions(sim)
    ball = ball_position(sim)
    reach = sim.mesh.spacing * sim.scale + sim.ball_offset
    near = np.linalg.norm(nodes[:, :2] - ball[:2], axis=1) <= reach
    if not np.any(near):
        return
    lift = float(nodes[near, 2].max()) + 2 * sim.ball_offset - ball[2]
    if lift > 0:
        sim.data.qpos[sim.ball_qpos + 2] += lift
    sim.data.qvel[sim.ball_dof:sim.ball_dof + 6] = 0.0
    mujoco.mj_forward(sim.model, sim.data)


def _speeds(sim: SheetSim) -> tuple[float, float]:
    """Largest speed of the ball's centre and of any node (slide-joint rate), m/s."""
    vel = np.asarray(sim.data.qvel)
    v_ball = float(np.linalg.norm(vel[sim.ball_dof:sim.ball_dof + 3]))
    others = np.delete(vel, np.arange(sim.ball_dof, sim.ball_dof + 6))
    return v_ball, float(np.max(np.abs(others))) if others.size else 0.0


def settle_phase(sim: SheetSim, max_time: float, trace: list | None = None,
                 frames: list | None = None, speed: float = _tol.SETTLE_SPEED,
                 watch: bool = False) -> tuple[str, float]:
    """Step until the ball is slower than ``speed`` and every node slower than ten times
    that (checked every ``CHECK_INTERVAL``), or ``max_time`` passes; with ``watch``, stop
    as soon as the ball has left the sheet (:func:`left_sheet`).

    Returns (outcome, simulated time taken in s); outcome is ``"settled"``,
    ``"moving"`` (time limit), ``"diverged"`` (non-finite state, or one of MuJoCo's own
    instability warnings: bad qpos/qvel/qacc, constraint or contact buffer full) or
    ``"left"``."""
    import mujoco

    m, d = sim.model, sim.data
    chunk = max(1, int(round(_tol.CHECK_INTERVAL / m.opt.timestep)))
    t0 = d.time
    while d.time - t0 < max_time:
        for _ in range(chunk):
            mujoco.mj_step(m, d)
        if trace is not None:
            trace.append((d.time, *ball_position(sim)))
        if frames is not None:
            frames.append(node_positions(sim))
        if not np.all(np.isfinite(d.qpos)) or _unstable(sim):
            return "diverged", d.time - t0
        if watch and left_sheet(sim):
            return "left", d.time - t0
        vb, vn = _speeds(sim)
        if vb < speed and vn < speed * 10:
            return "settled", d.time - t0
    return "moving", d.time - t0


def _unstable(sim: SheetSim) -> bool:
    """MuJoCo flagged a bad position, velocity or acceleration (it then resets the state,
    which must not pass for a rest state) or ran out of room for constraints, or a node
    flew out of the sheet's reach (:func:`_escaped`)."""
    import mujoco

    w = sim.data.warning
    return _escaped(sim) or any(w[int(k)].number > 0 for k in (
        mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQPOS,
        mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_CNSTRFULL,
        mujoco.mjtWarning.mjWARN_CONTACTFULL))


def _escaped(sim: SheetSim) -> bool:
    """A node is farther than ``ESCAPE_DISTANCE`` from every robot's holding point: no
    state of an inextensible sheet has one there, so the solver has lost the model. Seen
    with the contact node pinned under a held ball at meshes 19-32 of a 971 mm sheet
    (Newton at its iteration cap on thousands of active tendon limits, the ball metres
    away with finite values and no warning from MuJoCo). The ball is not tested: a
    dropped one may start anywhere (``settle(start=...)``)."""
    corners = np.asarray(sim.data.mocap_pos[sim.corner_mocap])
    nodes = node_positions(sim)
    gap = np.linalg.norm(nodes[:, None, :] - corners[None, :, :], axis=2).min(axis=1)
    return bool(gap.max() > _tol.ESCAPE_DISTANCE)


def left_sheet(sim: SheetSim) -> bool:
    """The untied ball is off the sheet: its centre is lower than the sheet's lowest node
    (it went through; a ball on the sheet is always above that node, the sheet being a
    surface over its nodes), or no sheet triangle lies straight below its centre and it
    does not touch the sheet (it fell off; a ball resting in the tip of a crease touches
    the sheet although the folded triangles around the tip's node need not cover the
    point straight above it)."""
    if sim.tie >= 0 and sim.data.eq_active[sim.tie]:
        return False
    nodes = node_positions(sim)
    ball = ball_position(sim)
    if ball[2] < float(nodes[:, 2].min()):
        return True
    return sim.data.ncon == 0 and surface_below(nodes, sim.mesh.triangles, ball) is None


def object_on_sheet(sim: SheetSim) -> tuple[np.ndarray, np.ndarray] | None:
    """The sheet point under the ball's centre: world position (3,) and flat sheet
    coordinates (2,), both in scenario units; None when the ball is off the sheet
    (:func:`left_sheet`). In the tip of a crease, where no triangle covers the point
    under the centre, the nearest node stands for it (its height, under the centre)."""
    if sim.tie >= 0 and sim.data.eq_active[sim.tie]:
        k = sim.mesh.contact
        return node_positions(sim)[k] / sim.scale, sim.mesh.nodes[k].copy()
    nodes = node_positions(sim)
    if left_sheet(sim):
        return None
    hit = surface_below(nodes, sim.mesh.triangles, ball_position(sim))
    if hit is None:
        ball = ball_position(sim)
        k = int(np.argmin(np.linalg.norm(nodes - ball, axis=1)))
        return np.append(ball[:2], nodes[k, 2]) / sim.scale, sim.mesh.nodes[k].copy()
    z, tri, bary = hit
    corners = sim.mesh.triangles[tri]
    xy = ball_position(sim)[:2]
    flat = bary @ sim.mesh.nodes[corners]
    return np.append(xy, z) / sim.scale, flat


def _contact_tendons(sim: SheetSim) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tendons at their limit that end at the contact node: MuJoCo's constraint force on
    each (N), the node at the other end, and the tendon ids."""
    import mujoco

    d = sim.data
    k = sim.mesh.contact
    rows = np.flatnonzero(np.asarray(d.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON))
    ids = np.asarray(d.efc_id)[rows]
    force = np.abs(np.asarray(d.efc_force)[rows])
    pairs = sim.tendon_pairs[ids]
    at = (pairs[:, 0] == k) | (pairs[:, 1] == k)
    other = np.where(pairs[at, 0] == k, pairs[at, 1], pairs[at, 0])
    return force[at], other, ids[at]


def sliding_force(sim: SheetSim) -> np.ndarray:
    r"""Least net pull on the tied contact node resolved in the flat sheet,
    :math:`\sum_j T_j (\mathbf{v}_j - \mathbf{v}_o) / |\mathbf{v}_j - \mathbf{v}_o|`,
    N, shape (2,).

    A frictionless object at the contact point is in equilibrium on the sheet only when
    this vanishes: with taut's weights it is :math:`(mg/d) \sum_i w_i (\mathbf{v}_i -
    \mathbf{v}_o) = 0` (docs/sheet_kinematics.md §3); a non-zero value means the sheet
    slides under the object.

    With a straight tendon from the contact node to every corner (``corner_tendons``),
    it is the pull of the rigid taut cables the simulation found
    (:func:`_taut_cable_pull`): the corner tendons at their limit, with the node at the
    lowest point they let it hang. MuJoCo's soft limits stretch each tendon by an amount
    that grows with its force (0.2-0.5 mm on the 1 m simulated sheet), which moves the node
    0.4-2 mm (scenario) off the point where those cables hang; at that point a stable
    state's cables pull sideways with up to 0.05 of the weight, a floor that does not
    fall with the mesh (it is set by the limits' softness, in metres) and that hid
    non-equilibria pulled by 0.001-0.04 (issue 31). Moved back onto the cables, stable
    states read below 1e-12 and those non-equilibria their model pull
    (examples/physics/README.md, "Hold resolution"). The rigid reading is the stiff limit
    of the force reading: with stiffer limits (SOLIMP ``dmin`` 0.9999, time step 4 to
    0.5 ms at a fixed node mass) the stretch fell to 1e-4 mm and, at rest, the force
    reading's difference from the rigid one fell with it, to 2.2e-5 of the weight at the
    worst stable state of issue 31's sample (0.051 with the defaults; same README,
    "The rigid reading is the stiff limit of the force reading").

    Otherwise, or when those cables cannot carry the weight with non-negative tensions
    (other tendons at the node carry part of it), it is the pull of the tendon forces
    MuJoCo's solver found (:func:`_force_pull`).
    """
    pull = _taut_cable_pull(sim)
    return _force_pull(sim) if pull is None else pull


def _taut_cable_pull(sim: SheetSim) -> np.ndarray | None:
    """Least pull (N, (2,)) on the contact node of the corner tendons the simulation has
    at their limit, read as rigid cables: the lowest point where the node can hang on
    them (:func:`lowest_point_load` from the node's simulated position, over those
    cables only), and the tensions of the ones taut there (within ``TAUT_LENGTH``) that
    carry the object's weight with the least sideways pull (:func:`least_pull`). None
    without a tendon from the node to every corner, with none at its limit, or when they
    cannot carry the weight."""
    k = sim.mesh.contact
    corners = sim.mesh.corners
    ends = sim.tendon_pairs[(sim.tendon_pairs == k).any(axis=1)].ravel()
    if k in corners or not np.isin(corners, ends).all():
        return None
    _, other, _ = _contact_tendons(sim)
    at = other[np.isin(other, corners)]
    if len(at) == 0:
        return None
    anchors = np.asarray(sim.data.mocap_pos[sim.corner_mocap])[
        [int(np.flatnonzero(corners == o)[0]) for o in at]]
    plan = sim.mesh.nodes * sim.scale
    p = lowest_point_load(plan[at], anchors[:, :2], float(anchors[0, 2]), plan[k],
                          node_positions(sim)[k])
    flat = plan[at] - plan[k]
    rest = np.linalg.norm(flat, axis=1)
    space = anchors - p
    length = np.linalg.norm(space, axis=1)
    taut = length >= rest * (1 - _tol.TAUT_LENGTH)
    if not taut.any():
        return None
    pull, residual = least_pull(np.zeros(2), flat[taut] / rest[taut, None],
                                space[taut] / length[taut, None], np.array([0.0, 0.0, 1.0]))
    return None if residual > _tol.BALANCE_SLACK else pull * sim.ball_mass * GRAVITY


def _force_pull(sim: SheetSim) -> np.ndarray:
    r"""Least pull (N, (2,)) of the tendon forces MuJoCo's solver found at the contact node.

    With four or more taut straight tendons from the contact node to held corners, the
    point load is statically indeterminate: the corner tensions :math:`T_J` that balance
    it form a family :math:`T_J + N s \ge 0` (:math:`N` spans the null space of their
    unit directions in space, read from the simulated positions), and which member the
    solver returns is set by the soft limits' compliance, not by the object. The object
    is held when *some* member pulls it nowhere, so the pull returned is the least over
    the family (:func:`least_pull`). With three or fewer the family is the measured
    forces alone."""
    k = sim.mesh.contact
    force, other, _ = _contact_tendons(sim)
    u = sim.mesh.nodes[other] - sim.mesh.nodes[k]
    u /= np.linalg.norm(u, axis=1)[:, None]
    pull = (force[:, None] * u).sum(axis=0)
    corner = np.isin(other, sim.mesh.corners)
    if corner.sum() < 4:
        return pull
    x = node_positions(sim)
    space = x[other[corner]] - x[k]
    space /= np.linalg.norm(space, axis=1)[:, None]
    fixed = pull - (force[corner, None] * u[corner]).sum(axis=0)
    least, _ = least_pull(fixed, u[corner], space, space.T @ force[corner])
    return least


def release(sim: SheetSim) -> None:
    """Let a ball held over one place (``xy_lock``) go where it is, at rest."""
    import mujoco

    m, d = sim.model, sim.data
    if not sim.xy_lock:
        return
    d.eq_active[list(sim.xy_lock)] = 0
    d.qvel[sim.ball_dof:sim.ball_dof + 6] = 0.0
    mujoco.mj_forward(m, d)
