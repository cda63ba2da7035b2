"""The simulated cable robot (private to the control simulation): a 6-DoF rigid platform on
elastic unilateral cables wound on winches, batched over B plants (Monte Carlo).

State per plant: centre of mass ``x_c`` and velocity ``v_c`` (world), rotation ``R`` and body
angular velocity ``w_b``, unstretched cable lengths ``L0`` (m), motor speeds (rad/s) and the
servo-drive integrators (N m). Forces: gravity, cable tensions
``T_i = max(0, (EA (L_i - L0_i) + d (L_dot_i - L0_dot_i)) / (L0_i + rho_i))`` along ``u_i``
(FASTKIT eq. 18; ``rho_i`` the routed length between drum and exit), and an optional constant
external wrench. Winches (friction with stiction, gear loss with the direction of power flow,
torque saturation at the peak torque): see :mod:`taut.cdpr.control.dynamics`.

Integrator: semi-implicit (symplectic) Euler with ``substeps`` steps per control period: the
velocities (platform and rotors) are advanced with the forces at the current configuration,
then the configuration with the new velocities, the rotation on SO(3) by the exponential map
(``R <- R exp(h [w_b])``, so R stays orthonormal); the rotors' friction is implicit (stick
and breakaway, :meth:`DynamicsModel.friction_step`). It is first-order accurate and symplectic:
without losses its energy error stays bounded (no drift), which the tests check over 2 s. It
is stable while ``omega_max h < 2`` for the stiffest mode ``omega_max`` of the linearised
platform-cable-rotor system; :func:`stiffest_mode` computes it, and a step with
``omega_max h > taut.cdpr._tol.STABILITY_OMEGA_H`` is refused before the run.

Energy: with no damping, friction or efficiency loss and constant motor torques the model is
conservative up to one term: the strain energy ``EA (L - L0)^2 / (2 L0)`` of a cable whose
unstretched length changes pulls the drum with ``T + T^2 / (2 EA)`` while the model (like
the real drum) feels ``T``; for FASTKIT ``T / EA ~ 1e-3``, so total energy is conserved to
~2e-5 relative over 2 s (tests/cdpr/control/test_control_sim.py). With losses,
:class:`EnergyLedger` books the motors' work and what the gearboxes, the friction and the cable
damping dissipate over each step, so that work in = stored energy change + dissipated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._tol import EQUILIBRIUM_FD_STEP, EQUILIBRIUM_FORCE_TOL
from ..kinematics.forward import so3_exp
from .dynamics import DynamicsModel
from ..kinematics.cables import rotation_matrices
from ..model.robot import CableRobot
from .model_errors import PlantPerturbation


@dataclass
class PlantState:
    """Mutable batched state (B plants); arrays are updated in place by :meth:`Plant.step`."""

    xc: np.ndarray        # (B, 3) centre of mass, m
    vc: np.ndarray        # (B, 3) m/s
    R: np.ndarray         # (B, 3, 3)
    wb: np.ndarray        # (B, 3) body angular velocity, rad/s
    L0: np.ndarray        # (B, m) unstretched lengths, m
    speed: np.ndarray     # (B, m) motor speeds, rad/s (positive pays cable out)
    integ: np.ndarray     # (B, m) drive speed-loop integrators, N m


class Plant:
    """Batched plant of ``len(perturbations)`` copies of ``robot`` with their model errors.

    Parameters
    ----------
    robot, dynamics
        Nominal model; each plant applies its :class:`PlantPerturbation`.
    perturbations : list of PlantPerturbation
    external_wrench : (6,), optional
        Constant extra wrench on the platform (N, then N m about the centre of mass).
    """

    def __init__(self, robot: CableRobot, dynamics: DynamicsModel,
                 perturbations: list[PlantPerturbation], external_wrench: Any = None) -> None:
        self.robot, self.dyn = robot, dynamics
        B = len(perturbations)
        self.B = B
        ms = np.array([p.mass_scale for p in perturbations])
        ps = np.array([p.payload_scale for p in perturbations])
        com, inertia = moving_body(robot, ps)                    # (B, 3), (B, 3, 3)
        self.com_local = com                                     # P -> CoM, platform frame
        self.mass = ms * (robot.platform.mass + ps * robot.payload.mass)       # (B,)
        self.inertia = ms[:, None, None] * inertia               # (B, 3, 3) about the CoM
        self.inertia_inv = np.linalg.inv(self.inertia)
        self.attach_c = robot.attach_local.T[None] - com[:, :, None]   # (B, 3, m) from CoM
        self.exit_offsets = np.stack([p.exit_offsets for p in perturbations]).transpose(0, 2, 1)
        self.length_offsets = np.stack([p.length_offsets for p in perturbations])
        # Per-winch plant parameters (B, m): efficiencies (capped at 1), friction scale,
        # rotor inertia.
        es = np.stack([p.efficiency_scales for p in perturbations])
        self.eta = np.minimum(dynamics.efficiency * es, 1.0)
        eta_b = dynamics.efficiency if dynamics.backdrive_efficiency is None \
            else dynamics.backdrive_efficiency
        self.eta_b = np.minimum(eta_b * es, 1.0)
        self.friction_scale = np.array([p.friction_scale for p in perturbations])[:, None] \
            * np.stack([p.friction_scales for p in perturbations])
        self.rotor_inertia = dynamics.rotor_inertia * np.stack(
            [p.inertia_scales for p in perturbations])
        self.routing = np.repeat(dynamics.routing(robot.m)[None], B, axis=0)   # (B, m), m
        self.g = robot.gravity
        ext = np.zeros(6) if external_wrench is None else np.asarray(external_wrench, float)
        self.f_ext, self.m_ext = ext[:3], ext[3:]
        # Constant blocks that turn the per-step cross products into matrix products.
        skews = np.stack([_skew(a.T) for a in self.attach_c])          # (B, m, 3, 3)
        Bn, m = skews.shape[:2]
        self._skew_row_T = np.swapaxes(np.concatenate(list(np.swapaxes(skews, 0, 1)), axis=2),
                                       1, 2).copy()                      # (B, 3m, 3)
        self._skew_stack_T = np.swapaxes(skews.reshape(Bn, 3 * m, 3), 1, 2).copy()  # (B, 3, 3m)
        self._skew_com_T = np.swapaxes(_skew(self.com_local), 1, 2).copy()        # (B, 3, 3)
        self._inv_mass = (1.0 / self.mass)[:, None]
        self._inertia_T = np.swapaxes(self.inertia, 1, 2).copy()
        self._inertia_inv_T = np.swapaxes(self.inertia_inv, 1, 2).copy()

    # -- geometry --------------------------------------------------------------------------
    def cables(self, s: PlantState, exits: np.ndarray, exit_vel: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Tensions (B, m), unit vectors (B, 3, m) and CoM-to-attachment vectors (B, 3, m) for
        world exits (3, m) (nominal, before offsets) moving at ``exit_vel`` (3, m)."""
        B = s.xc.shape[0]
        r = s.R @ self.attach_c
        vec = (exits - r) + (self.exit_offsets - s.xc[:, :, None])
        L = np.sqrt((vec * vec).sum(axis=1))
        u = vec / L[:, None, :]
        stretch = L - s.L0
        elastic = s.L0 + self.routing
        d = self.dyn
        if d.cable_damping > 0.0:
            # velocity of the attachments: v_c + R (w_b x b_i) = v_c - R [b_i]x w_b
            bxw = (s.wb[:, None, :] @ self._skew_stack_T)[:, 0].reshape(B, -1, 3)
            va = s.vc[:, :, None] - s.R @ np.swapaxes(bxw, 1, 2)
            # strain rate: L_dot - L0_dot (paying out at the rotor speed is not stretching)
            sdot = (u * (exit_vel - va)).sum(axis=1) - d.length_per_rad * s.speed
            f = (d.cable_stiffness * stretch + d.cable_damping * sdot) / elastic
            T = np.where(stretch > 0.0, np.maximum(f, 0.0), 0.0)
        else:
            T = np.maximum(d.cable_stiffness * stretch / elastic, 0.0)
        return T, u, r

    def stretches(self, s: PlantState, exits: np.ndarray) -> np.ndarray:
        """Cable stretches ``L - L0`` (B, m), m, for world exits (3, m)."""
        vec = (exits - s.R @ self.attach_c) + (self.exit_offsets - s.xc[:, :, None])
        return np.sqrt((vec * vec).sum(axis=1)) - s.L0

    def motor_torque(self, s: PlantState, mode: str, command: np.ndarray, h: float
                     ) -> np.ndarray:
        """Motor torques (B, m), N m, saturated at the peak torque: ``command`` directly in
        ``"torque"`` mode, or
        the drive's PI speed loop towards the speed set-points ``command`` (rad/s, clipped to
        the speed limit) in ``"speed"`` mode (its integrator advances by ``h``)."""
        d = self.dyn
        lim = d.peak_torque
        if mode == "torque":
            return np.clip(command, -lim, lim)
        err = s.speed - np.clip(command, -d.motor_speed_limit, d.motor_speed_limit)
        tau = np.clip(d.drive_speed_gain * err + s.integ, -lim, lim)
        s.integ[:] = np.clip(s.integ + h * d.drive_integral_gain * err, -lim, lim)
        return tau

    def step(self, s: PlantState, h: float, exits: np.ndarray, exit_vel: np.ndarray,
             tau: np.ndarray, ledger: "EnergyLedger | None" = None) -> np.ndarray:
        """Advance every plant by ``h`` s with motor torques ``tau`` (B, m); returns the
        tensions (B, m) at the start of the step. A ``ledger`` books the step's energy flows."""
        B = s.xc.shape[0]
        T, u, r = self.cables(s, exits, exit_vel)
        stretch0 = self.stretches(s, exits) if ledger is not None else None
        Tu = u * T[:, None, :]
        F = Tu.sum(axis=2) + self.f_ext
        # Body-frame moment about the CoM: sum_i b_i x (R^T f_i) = [[b_1]x ... [b_m]x] g.
        g = np.swapaxes(s.R, 1, 2) @ Tu
        tb = (np.swapaxes(g, 1, 2).reshape(B, 1, -1) @ self._skew_row_T)[:, 0] \
            + self.m_ext @ s.R
        Iw = (s.wb[:, None, :] @ self._inertia_T)[:, 0, :]
        gyro = _cross_rows(s.wb, Iw)
        s.vc += h * (F * self._inv_mass + self.g)
        s.wb += h * ((tb - gyro)[:, None, :] @ self._inertia_inv_T)[:, 0, :]
        s.xc += h * s.vc
        s.R[:] = s.R @ so3_exp(h * s.wb)
        d = self.dyn
        k = d.length_per_rad
        gear = d.gear_loss(tau, T, s.speed, self.eta, self.eta_b)
        if ledger is not None and stretch0 is not None:
            el0 = d.cable_stiffness * np.maximum(stretch0, 0.0) / (s.L0 + self.routing)
        s.speed[:], fric = d.friction_step(s.speed, k * T - tau - gear, h, self.rotor_inertia,
                                           self.friction_scale)
        s.L0 += (h * k) * s.speed
        if ledger is not None and stretch0 is not None:
            ledger.book(self, s, h, exits, tau, T, gear, fric, stretch0, el0)
        return T

    # -- measurements and energy -----------------------------------------------------------
    def pose_of(self, s: PlantState) -> tuple[np.ndarray, np.ndarray]:
        """Platform reference point P (B, 3) and its velocity (B, 3)."""
        rc = (s.R @ self.com_local[:, :, None])[:, :, 0]
        # v_P = v_c - R (w_b x c) = v_c + R ([c]x w_b)
        cxw = (s.wb[:, None, :] @ self._skew_com_T)[:, 0]
        return s.xc - rc, s.vc + (s.R @ cxw[:, :, None])[:, :, 0]

    def energy(self, s: PlantState, exits: np.ndarray, tau: np.ndarray,
               L0_start: np.ndarray) -> np.ndarray:
        """Total mechanical energy (B,), J: platform and rotor kinetic energy, gravity (zero
        at the ground), cable strain energy ``EA (L - L0)^2 / (2 (L0 + rho))`` and the potential of
        constant motor torques ``tau N / r (L0 - L0_start)`` (valid for constant tau; a
        conservative check needs the lossless model, see ``DynamicsModel.without_losses``)."""
        d = self.dyn
        stretch = np.maximum(self.stretches(s, exits), 0.0)
        ke = 0.5 * self.mass * np.einsum("bi,bi->b", s.vc, s.vc) + 0.5 * np.einsum(
            "bi,bij,bj->b", s.wb, self.inertia, s.wb) + 0.5 * np.einsum(
            "bm,bm,bm->b", self.rotor_inertia, s.speed, s.speed)
        pe = -self.mass * (s.xc @ self.g) + 0.5 * np.einsum(
            "bm,bm->b", d.cable_stiffness * stretch ** 2, 1.0 / (s.L0 + self.routing))
        pm = np.einsum("bm,bm->b", tau / d.length_per_rad, s.L0 - L0_start)
        return ke + pe + pm


@dataclass
class EnergyLedger:
    """Energy flows of B plants summed over the steps booked (J, each (B,)): the motors' work
    on the rotors (``input``; positive when they wind cable in against the load), what the
    gearboxes, the rotor friction and the cable damping dissipate, and ``spooling``, the
    strain energy ``T^2 / (2 EA)`` per metre that the model's drum does not account for when
    it pays out or winds in cable (see the module docstring; ~``T / EA`` of the work). Over
    any run ``input = stored energy change + gear + friction + damping + spooling`` up to the
    integrator's O(h) error (the stored energy is :meth:`Plant.energy` with zero torques);
    the terms use the step's end velocities, as the semi-implicit Euler step does.
    """

    input: np.ndarray
    gear: np.ndarray
    friction: np.ndarray
    damping: np.ndarray
    spooling: np.ndarray

    @classmethod
    def zeros(cls, B: int) -> "EnergyLedger":
        """An empty ledger for B plants."""
        return cls(np.zeros(B), np.zeros(B), np.zeros(B), np.zeros(B), np.zeros(B))

    @property
    def dissipated(self) -> np.ndarray:
        """Gear + friction + damping losses (B,), J (never negative)."""
        return self.gear + self.friction + self.damping

    def book(self, plant: "Plant", s: PlantState, h: float, exits: np.ndarray,
             tau: np.ndarray, T: np.ndarray, gear: np.ndarray, fric: np.ndarray,
             stretch0: np.ndarray, elastic0: np.ndarray) -> None:
        """Add one step: torques ``tau``, tensions ``T``, stretches ``stretch0`` and elastic
        tensions ``elastic0`` at its start, gear and friction torques ``gear``, ``fric``
        (B, m), and the state ``s`` after it."""
        w = s.speed
        self.input += (-tau * w).sum(axis=1) * h          # tau winds in, w pays out
        self.gear += (gear * w).sum(axis=1) * h
        self.friction += (fric * w).sum(axis=1) * h
        # cable damping: the tension above the elastic one times the stretch increment
        self.damping += ((T - elastic0) * (plant.stretches(s, exits) - stretch0)).sum(axis=1)
        EA = plant.dyn.cable_stiffness
        self.spooling += (elastic0 ** 2 / (2.0 * EA) * (h * plant.dyn.length_per_rad) * w
                          ).sum(axis=1)


def moving_body(robot: CableRobot, payload_scale: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """Centre of mass (B, 3) in the platform frame (from P, m) and inertia about it (B, 3, 3),
    kg m^2, of the platform and its payload (mass and own inertia x ``payload_scale`` (B,)),
    by the parallel-axis theorem."""
    mp, com_p, Ip = robot.platform.mass, robot.platform.com, robot.platform.inertia
    ml = robot.payload.mass * np.asarray(payload_scale, dtype=float)
    com_l = robot.payload.com
    com = (mp * com_p[None] + ml[:, None] * com_l[None]) / (mp + ml)[:, None]
    dp, dl = com_p[None] - com, com_l[None] - com

    def steiner(d: np.ndarray) -> np.ndarray:
        return np.einsum("bi,bi->b", d, d)[:, None, None] * np.eye(3) \
            - d[:, :, None] * d[:, None, :]

    inertia = Ip[None] + mp * steiner(dp) + ml[:, None, None] * steiner(dl) \
        + np.asarray(payload_scale, dtype=float)[:, None, None] * robot.payload.inertia[None]
    return com, inertia


def _skew(r: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[r]x`` (n, 3, 3) of vectors (n, 3)."""
    S = np.zeros((len(r), 3, 3))
    S[:, 0, 1], S[:, 0, 2], S[:, 1, 2] = -r[:, 2], r[:, 1], -r[:, 0]
    S[:, 1, 0], S[:, 2, 0], S[:, 2, 1] = r[:, 2], -r[:, 1], r[:, 0]
    return S


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (B, 3) arrays (cheaper than ``np.cross`` on tiny arrays)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=1)


def stiffest_mode(plant: Plant, state: PlantState, exits: np.ndarray) -> float:
    """Largest natural frequency (rad/s) of the linearised platform-cable-rotor system at the
    state of plant 0: ``sqrt(max eig(M^-1 K))`` with generalised coordinates (platform twist
    about the CoM, 6; unstretched lengths, m) and the axial cable stiffnesses
    ``k_i = EA / (L0_i + rho_i)`` (taut cables only) and, per cable, the lightest rotor of all plants.
    The integrator needs ``omega_max h < 2``."""
    d = plant.dyn
    T, u, r = plant.cables(state, exits, np.zeros_like(exits))
    u0, r0 = u[0].T, r[0].T
    G = np.hstack([u0, np.cross(r0, u0)])                  # (m, 6): dL = -G dx
    k = np.where(T[0] > 0, d.cable_stiffness / (state.L0[0] + plant.routing[0]), 0.0)
    m = plant.robot.m
    J = np.hstack([-G, -np.eye(m)])                         # stretch = J [dx; dL0]
    K = J.T @ (k[:, None] * J)
    Minv_mat = np.zeros((6 + m, 6 + m))
    Minv_mat[:3, :3] = np.eye(3) / plant.mass[0]
    Rw = state.R[0]
    Minv_mat[3:6, 3:6] = Rw @ plant.inertia_inv[0] @ Rw.T
    # the lightest rotor of any plant per cable (winch errors): conservative for the batch
    Minv_mat[6:, 6:] = np.diag(d.length_per_rad ** 2 / plant.rotor_inertia.min(axis=0))
    ev = np.linalg.eigvals(Minv_mat @ K)
    return float(np.sqrt(max(float(np.max(ev.real)), 0.0)))


def initial_state(plant: Plant, exits: np.ndarray, L0: np.ndarray, guess: np.ndarray
                  ) -> PlantState:
    """Every plant at rest in elastic static equilibrium with unstretched lengths ``L0``
    (B, m) under gravity (the external wrench, a disturbance, starts acting at the first
    step), found by Newton's method on the force and moment balance from the pose ``guess``
    (6,) of P; drives initialised to hold the tensions (at rest the regularised gearbox loss
    vanishes: ``tau = kl T``)."""
    B = plant.B
    R0 = np.repeat(rotation_matrices(guess[None, 3:]), B, axis=0)
    xc0 = guess[:3] + (R0 @ plant.com_local[:, :, None])[:, :, 0]
    s = PlantState(xc0, np.zeros((B, 3)), R0, np.zeros((B, 3)), L0.copy(),
                   np.zeros_like(L0), np.zeros_like(L0))
    zero_v = np.zeros_like(exits)

    def residual(st: PlantState) -> np.ndarray:
        T, u, r = plant.cables(st, exits, zero_v)
        Tu = u * T[:, None, :]
        F = Tu.sum(axis=2) + plant.mass[:, None] * plant.g
        M = np.cross(r, Tu, axis=1).sum(axis=2)
        return np.hstack([F, M])

    eps = EQUILIBRIUM_FD_STEP
    for _ in range(50):
        res = residual(s)
        if np.abs(res).max() < EQUILIBRIUM_FORCE_TOL:
            break
        Jac = np.empty((B, 6, 6))
        for j in range(6):
            dx = np.zeros((B, 6))
            dx[:, j] = eps
            Jac[:, :, j] = (residual(_moved(s, dx)) - res) / eps
        step = -np.einsum("bij,bj->bi", np.linalg.pinv(Jac), res)   # robust if singular
        s = _moved(s, step)
    T, _, _ = plant.cables(s, exits, zero_v)
    d = plant.dyn
    s.integ[:] = d.length_per_rad * T
    return s


def _moved(s: PlantState, dx: np.ndarray) -> PlantState:
    """Copy of ``s`` with the CoM moved by dx[:, :3] and rotated by exp(dx[:, 3:]) (world)."""
    return PlantState(s.xc + dx[:, :3], s.vc.copy(), so3_exp(dx[:, 3:]) @ s.R, s.wb.copy(),
                      s.L0.copy(), s.speed.copy(), s.integ.copy())
