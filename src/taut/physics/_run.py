"""Driving a compiled sheet model through its phases: ramp, settle, release."""

from __future__ import annotations

import numpy as np

from .._units import GRAVITY
from . import _tol
from ._sheet_model import SheetSim
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
    """Move the corners from the flat copy to the robots with gravity off."""
    import mujoco

    m, d = sim.model, sim.data
    m.opt.gravity[:] = 0.0
    steps = max(1, int(round(_tol.RAMP_TIME / m.opt.timestep)))
    for k in range(1, steps + 1):
        s = k / steps
        s = s * s * (3 - 2 * s)            # smooth start and stop
        d.mocap_pos[sim.corner_mocap] = (1 - s) * sim.corner_start + s * sim.corner_goal
        mujoco.mj_step(m, d)
    m.opt.gravity[:] = (0.0, 0.0, -GRAVITY)


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
    ``"moving"`` (time limit), ``"diverged"`` (non-finite state) or ``"left"``."""
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
        if not np.all(np.isfinite(d.qpos)):
            return "diverged", d.time - t0
        if watch and left_sheet(sim):
            return "left", d.time - t0
        vb, vn = _speeds(sim)
        if vb < speed and vn < speed * 10:
            return "settled", d.time - t0
    return "moving", d.time - t0


def left_sheet(sim: SheetSim) -> bool:
    """The untied ball is off the sheet: no sheet triangle lies straight below its centre,
    or its centre is lower than the sheet's lowest node (it went through; a ball on the
    sheet is always above that node, the sheet being a surface over its nodes)."""
    if sim.tie >= 0 and sim.data.eq_active[sim.tie]:
        return False
    nodes = node_positions(sim)
    ball = ball_position(sim)
    return (ball[2] < float(nodes[:, 2].min())
            or surface_below(nodes, sim.mesh.triangles, ball) is None)


def object_on_sheet(sim: SheetSim) -> tuple[np.ndarray, np.ndarray] | None:
    """The sheet point under the ball's centre: world position (3,) and flat sheet
    coordinates (2,), both in scenario units; None when the ball is off the sheet."""
    if sim.tie >= 0 and sim.data.eq_active[sim.tie]:
        k = sim.mesh.contact
        return node_positions(sim)[k] / sim.scale, sim.mesh.nodes[k].copy()
    nodes = node_positions(sim)
    hit = surface_below(nodes, sim.mesh.triangles, ball_position(sim))
    if hit is None:
        return None
    z, tri, bary = hit
    corners = sim.mesh.triangles[tri]
    xy = ball_position(sim)[:2]
    flat = bary @ sim.mesh.nodes[corners]
    return np.append(xy, z) / sim.scale, flat


def sliding_force(sim: SheetSim) -> np.ndarray:
    r"""Net pull of the sheet's tendons on the contact node resolved in the flat sheet,
    :math:`\sum_j T_j (\mathbf{v}_j - \mathbf{v}_o) / |\mathbf{v}_j - \mathbf{v}_o|`, N,
    shape (2,), with :math:`T_j` the tendon-limit forces MuJoCo's solver found.

    A frictionless object at the contact point is in equilibrium on the sheet only when
    this vanishes: with taut's weights it is :math:`(mg/d) \sum_i w_i (\mathbf{v}_i -
    \mathbf{v}_o) = 0` (docs/sheet_kinematics.md §3); a non-zero value means the sheet
    slides under the object.
    """
    import mujoco

    m, d = sim.model, sim.data
    k = sim.mesh.contact
    rows = np.flatnonzero(np.asarray(d.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON))
    ids = np.asarray(d.efc_id)[rows]
    force = np.abs(np.asarray(d.efc_force)[rows])
    pairs = sim.tendon_pairs[ids]
    at = (pairs[:, 0] == k) | (pairs[:, 1] == k)
    other = np.where(pairs[at, 0] == k, pairs[at, 1], pairs[at, 0])
    u = sim.mesh.nodes[other] - sim.mesh.nodes[k]
    u /= np.linalg.norm(u, axis=1)[:, None]
    return (force[at, None] * u).sum(axis=0)


def release(sim: SheetSim) -> None:
    """Let a ball held over one place (``xy_lock``) go where it is, at rest."""
    import mujoco

    m, d = sim.model, sim.data
    if not sim.xy_lock:
        return
    d.eq_active[list(sim.xy_lock)] = 0
    d.qvel[sim.ball_dof:sim.ball_dof + 6] = 0.0
    mujoco.mj_forward(m, d)
