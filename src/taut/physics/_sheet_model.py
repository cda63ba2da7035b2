"""The sheet, its robots and the object as a MuJoCo model built with ``mujoco.MjSpec``.

Recipe (measured, see examples/physics/README.md): the virtual variable cables model's
sheet is massless, perfectly flexible and inextensible (FK paper, Sec. II). MuJoCo's 2D
flex cloth with edge constraints cannot wrinkle and locks, so the sheet is a cloud of light,
gravity-compensated, lightly damped nodes, each with three slide joints, and inextensibility
is a tension-only tendon between node pairs (length limited to [0, flat distance]). A 2D
flex over the nodes is used only for ball-sheet collision. Robots' holding points are mocap
bodies at the hold height.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._units import GRAVITY
from . import _tol
from ._mesh import SheetMesh

__all__ = ["SheetSim", "build_sheet_sim", "align_flat"]


def align_flat(vertices: np.ndarray, formation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (2, 2) and translation (2,) putting the flat sheet over the formation
    (Procrustes fit, no reflection, no scaling): ``world = sheet @ Q.T + t``."""
    cv, cr = vertices.mean(axis=0), formation.mean(axis=0)
    H = (vertices - cv).T @ (formation - cr)
    U, _, Wt = np.linalg.svd(H)
    Q = (U @ Wt).T
    if np.linalg.det(Q) < 0:
        Wt[-1] *= -1
        Q = (U @ Wt).T
    return Q, cr - cv @ Q.T


@dataclass(eq=False)
class SheetSim:
    """A compiled sheet model and its data (mutable simulation state, private).

    Positions are in the simulation's metres; ``scale`` converts scenario units to them.
    """

    model: Any
    data: Any
    mesh: SheetMesh
    scale: float
    node_qpos: np.ndarray          # (M, 3) qpos addresses of each free node (-1: corner)
    node_body: np.ndarray          # (M,) body id of each node
    corner_mocap: np.ndarray       # (N,) mocap id of each corner
    corner_start: np.ndarray       # (N, 3) corner positions of the flat copy
    corner_goal: np.ndarray        # (N, 3) robots' holding points
    ball_body: int
    ball_qpos: int
    ball_dof: int
    ball_offset: float             # ball radius + flex radius, m
    ball_geom: int
    tie: int                       # equality id of the tie (-1: none)
    tendon_pairs: np.ndarray       # (P, 2) node pair of each tendon, in tendon order
    xy_lock: tuple[int, ...] = ()  # equality ids locking the ball's x and y slides
    ball_mass: float = _tol.BALL_MASS  # kg


def _node_positions(mesh: SheetMesh, Q: np.ndarray, t: np.ndarray, hold: float,
                    scale: float) -> np.ndarray:
    centre = mesh.nodes[mesh.corners].mean(axis=0)
    flat = centre + _tol.START_SHRINK * (mesh.nodes - centre)
    xy = (flat @ Q.T + t) * scale
    return np.column_stack([xy, np.full(len(xy), hold * scale)])


def _add_nodes(spec: Any, body_pos: np.ndarray, corners: set[int], dt: float,
               ball_mass: float) -> list[str]:
    """Node bodies; their mass scales with the ball's (``NODE_MASS_PER_DT2`` is per
    ``BALL_MASS``), so every mass, and with it every force, scales with the load and the
    motion does not change: the statics of a massless sheet do not depend on the load."""
    import mujoco

    mass = _tol.NODE_MASS_PER_DT2 * dt * dt * ball_mass / _tol.BALL_MASS
    damping = mass / _tol.NODE_DAMPING_TIME
    names = []
    for k, p in enumerate(body_pos):
        name = f"node{k}"
        b = spec.worldbody.add_body(name=name, pos=p.tolist())
        if k in corners:
            b.mocap = True
        else:
            b.mass = mass
            b.inertia = [mass * 1e-4] * 3
            b.explicitinertial = True
            b.gravcomp = 1.0
            for c, axis in zip("xyz", ((1, 0, 0), (0, 1, 0), (0, 0, 1))):
                b.add_joint(name=f"node{k}_{c}", type=mujoco.mjtJoint.mjJNT_SLIDE,
                            axis=list(axis), damping=damping)
        b.add_site(name=f"s{k}", size=[1e-3, 0, 0])
        # Flex vertices may not carry joint damping: the flex uses a jointless child.
        b.add_body(name=f"v{k}")
        names.append(f"v{k}")
    return names


def _add_tendons(spec: Any, pairs: np.ndarray, rest: np.ndarray) -> None:
    for (a, b), L in zip(pairs, rest):
        ten = spec.add_tendon(limited=True, range=[0.0, float(L)],
                              solref_limit=list(_tol.SOLREF), solimp_limit=list(_tol.SOLIMP))
        ten.wrap_site(f"s{a}")
        ten.wrap_site(f"s{b}")


def build_sheet_sim(mesh: SheetMesh, vertices: np.ndarray, formation: np.ndarray,
                    hold_height: float, *, ball_radius: float, ball_start: np.ndarray | None,
                    tie: bool, corner_tendons: bool, timestep: float = _tol.TIMESTEP,
                    hold_xy: bool = False, pin_contact: bool = False,
                    ball_mass: float = _tol.BALL_MASS) -> SheetSim:
    """Compile the model (reason for length: one linear recipe, step by step).

    ``ball_start`` (3,) in scenario units, ``ball_mass`` in kg; with ``tie`` the ball's
    centre is connected to the contact node and contacts are off (a point load). With
    ``hold_xy`` (and no tie) the ball moves on three slide joints and a ball joint instead
    of a free joint, and its two horizontal slides are locked (equality constraints
    ``xy_lock``) until :func:`taut.physics._run.release`: the ball presses the sheet down
    straight below its start with contacts on, so the sheet forms its pocket under the
    ball (a ball put on a sheet shaped by a point load can miss the pocket: it may be a
    narrow fold). With ``pin_contact`` the mesh's contact node is also kept straight below
    the ball until then.
    """
    import mujoco

    D = float(np.max(np.linalg.norm(vertices[:, None] - vertices[None], axis=2)))
    scale = _tol.SIM_DIAMETER / D
    Q, t = align_flat(vertices, formation)
    pos = _node_positions(mesh, Q, t, hold_height, scale)
    corners = [int(c) for c in mesh.corners]
    goal = np.column_stack([formation * scale, np.full(len(formation), hold_height * scale)])

    spec = mujoco.MjSpec()
    spec.modelname = "taut_sheet"
    opt = spec.option
    opt.timestep = timestep
    opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
    opt.gravity = [0.0, 0.0, -GRAVITY]
    opt.iterations = 50
    opt.ls_iterations = 20
    names = _add_nodes(spec, pos, set(corners), timestep, ball_mass)
    pairs, rest = mesh.pairs, mesh.rest * scale
    if corner_tendons:
        M = len(mesh.nodes)
        have = set(map(tuple, np.sort(pairs, axis=1).tolist()))
        extra = np.array([(c, k) for c in corners for k in range(M)
                          if k != c and (min(c, k), max(c, k)) not in have],
                         dtype=np.intp).reshape(-1, 2)
        if len(extra):
            pairs = np.vstack([pairs, extra])
            rest = np.concatenate([rest, np.linalg.norm(
                mesh.nodes[extra[:, 0]] - mesh.nodes[extra[:, 1]], axis=1) * scale])
    _add_tendons(spec, pairs, rest)

    h = mesh.spacing * scale
    flex_radius = _tol.FLEX_RADIUS * h
    flex = spec.add_flex(name="sheet")
    flex.dim = 2
    flex.vertbody = names
    flex.vert = [0.0] * (3 * len(names))
    flex.elem = mesh.triangles.ravel().tolist()
    flex.radius = flex_radius
    flex.contype = 1
    flex.conaffinity = 1
    flex.condim = 1
    flex.solref = list(_tol.SOLREF)
    flex.solimp = list(_tol.SOLIMP)
    flex.selfcollide = mujoco.mjtFlexSelf.mjFLEXSELF_NONE
    flex.rgba = [0.3, 0.5, 0.8, 1.0]

    r = ball_radius * scale
    offset = r + flex_radius
    if tie:
        start = pos[mesh.contact]
    elif ball_start is not None:
        start = np.asarray(ball_start, dtype=float) * scale
    else:
        start = np.append(goal[:, :2].mean(axis=0), hold_height * scale + 2 * offset)
    ball = spec.worldbody.add_body(name="ball", pos=start.tolist())
    ball_damping = ball_mass / _tol.BALL_DAMPING_TIME
    if hold_xy:
        for name, axis in (("x", (1, 0, 0)), ("y", (0, 1, 0)), ("z", (0, 0, 1))):
            ball.add_joint(name=f"ball_{name}", type=mujoco.mjtJoint.mjJNT_SLIDE,
                           axis=list(axis), damping=ball_damping)
        ball.add_joint(name="ball_turn", type=mujoco.mjtJoint.mjJNT_BALL,
                       damping=ball_damping)
        for name in ("ball_x", "ball_y"):          # slide stays at 0: xy stays at start
            spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, objtype=mujoco.mjtObj.mjOBJ_JOINT,
                              name1=name, data=[0.0] * 12,
                              solref=list(_tol.SOLREF), solimp=list(_tol.SOLIMP))
        if pin_contact and mesh.contact is not None and mesh.contact not in corners:
            # The contact node is kept straight below the ball (its x and y slides follow
            # the ball's, whose are locked): the sheet forms with taut's contact point
            # under the object instead of sliding to another pocket.
            k = mesh.contact
            for i, c in enumerate("xy"):
                shift = float(start[i] - pos[k, i])     # qpos0 of both slides is 0
                spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT,
                                  objtype=mujoco.mjtObj.mjOBJ_JOINT,
                                  name1=f"node{k}_{c}", name2=f"ball_{c}",
                                  data=[shift, 1.0] + [0.0] * 10,
                                  solref=list(_tol.SOLREF), solimp=list(_tol.SOLIMP))
    else:
        ball.add_joint(name="ball", type=mujoco.mjtJoint.mjJNT_FREE, damping=ball_damping)
    ball.add_geom(name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[r, 0, 0],
                  mass=ball_mass, contype=1, conaffinity=1, condim=1,
                  solref=list(_tol.SOLREF), solimp=list(_tol.SOLIMP), rgba=[0.9, 0.3, 0.2, 1.0])
    if tie:
        # Tied, the ball's centre is pinned to the contact node and contacts are off
        # (a point load, as in the model).
        spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_BODY,
                          name1="ball", name2=f"node{mesh.contact}", data=[0.0] * 12,
                          solref=list(_tol.SOLREF), solimp=list(_tol.SOLIMP))
    with warnings.catch_warnings():
        # The flex is for collision only: MuJoCo warns that it has no elasticity.
        warnings.simplefilter("ignore", UserWarning)
        model = spec.compile()
    if tie:
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    data = mujoco.MjData(model)
    node_body = np.array([model.body(f"node{k}").id for k in range(len(names))])
    node_qpos = np.full((len(names), 3), -1, dtype=np.intp)
    for k, b in enumerate(node_body):
        if model.body_jntnum[b] == 3:
            node_qpos[k] = model.jnt_qposadr[model.body_jntadr[b]] + np.arange(3)
    mocap = model.body_mocapid[node_body[corners]]
    bb = model.body("ball").id
    jid = model.body_jntadr[bb]
    sim = SheetSim(model, data, mesh, scale, node_qpos, node_body, mocap,
                   pos[corners].copy(), goal, bb, int(model.jnt_qposadr[jid]),
                   int(model.jnt_dofadr[jid]), offset, model.geom("ball").id,
                   0 if tie else -1, pairs,
                   tuple(range(model.neq)) if hold_xy and not tie else (), ball_mass)
    mujoco.mj_forward(model, data)
    return sim
