"""What a simulated controller measures (FASTKIT paper §2.2: the robot has no exteroceptive
sensor; its drives read motor encoders and currents).

:class:`Sensing` says which measurements a controller gets. By default (``Sensing()``) it
gets what FASTKIT has: quantised motor encoders (cable lengths and motor speeds) and the
drives' motor torques; the platform pose it uses is estimated by cable forward kinematics on
the measured lengths with the *nominal* model (exits, attachments, cable stiffness), and its
twist by the first-order model (eq. 1) from the measured cable rates, low-pass filtered.
``ideal_pose=True``
gives the controller the true pose and twist instead (an external tracker), for studies.

Estimator (private, numpy; the compiled loop mirrors it): with ``ra_i = R a_i`` and unit
vectors ``u_i`` from attachment to exit, the estimated cable lengths are
``L_i = L0_i + T_i (L0_i + rho_i) / EA`` (``T`` the load-cell tension when there is one,
else the reference tension of the nominal model; ``rho`` the routing length), the pose minimises ``sum (|e_i - p - R a_i| - L_i)^2``
by Gauss-Newton (rows ``[-u_i, -(ra_i x u_i)]``, warm-started, rotation updated on SO(3)),
and the twist solves the same rows in least squares against ``L_dot_i - u_i . e_dot_i`` with
``L_dot = kl theta_dot``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, get_args

import numpy as np

from ..._validate import as_bounded, as_choice, as_nonnegative
from ...errors import InvalidInputError
from ..kinematics.forward import so3_exp

__all__ = ["Sensing"]

#: Where a controller's tension measurement comes from.
TensionSource = Literal["current", "load_cell", "none"]


@dataclass(frozen=True)
class Sensing:
    """Measurements of a simulated controller.

    Parameters
    ----------
    ideal_pose : bool
        True: the controller sees the true platform pose and twist (an external tracker).
        False (default): it estimates them from the encoders with the nominal model.
    encoder_counts : float
        Encoder counts per motor revolution (*assumed* 2^17 = 131072, a 17-bit servo
        encoder: 0.38 um of cable per count through FASTKIT's 5:1 gearhead and 0.04 m drum).
        0 disables the quantisation.
    tension : {"current", "load_cell", "none"}
        The tension a controller sees (only ``VelocityController(tension_gain > 0)`` uses
        it): "current" (default, what FASTKIT's drives have) estimates it from the motor
        torque, speed and acceleration (encoder speed difference over a control period)
        with the nominal winch model (inertia, friction and gearbox loss compensated, so
        winch model errors bias it), low-pass filtered at ``velocity_filter``; "load_cell"
        measures it; "none" gives NaN.
    tension_noise : float
        Standard deviation of the tension measurement's white noise, N (default 0).
    velocity_filter : float
        Cut-off of the first-order low-pass filter on the estimated twist's deviation from
        the reference twist (so the filter adds no lag to the planned motion), Hz (default
        30; 0 disables it). Cable rates from the motor encoders carry the rotor-cable mode
        (~16 Hz for FASTKIT: ``EA / L`` against ``J (N / r)^2``), which unfiltered feedback
        into the task-space damping excites into a limit cycle (measured: 4 cm/s velocity
        error at rest, 35 mm drift); 10-30 Hz keeps the 3 Hz torque law stable. Not used
        with ``ideal_pose``.
    latency : float
        Delay from measurement to actuation, s (default 0), rounded to control periods.
    seed : int
        Seed of the noise (``numpy.random.default_rng``).

    Examples
    --------
    >>> Sensing().ideal_pose, Sensing().tension
    (False, 'current')
    """

    ideal_pose: bool = False
    encoder_counts: float = 131072.0
    tension: TensionSource = "current"
    tension_noise: float = 0.0
    velocity_filter: float = 30.0
    latency: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.ideal_pose, (bool, np.bool_)):
            raise InvalidInputError("sensing.ideal_pose", f"must be True or False, got "
                                                          f"{self.ideal_pose!r}")
        object.__setattr__(self, "ideal_pose", bool(self.ideal_pose))
        object.__setattr__(self, "encoder_counts",
                           as_nonnegative(self.encoder_counts, "sensing.encoder_counts"))
        as_choice(self.tension, get_args(TensionSource), "sensing.tension")
        object.__setattr__(self, "tension_noise", as_bounded(
            self.tension_noise, "sensing.tension_noise", 1.0e4, "N", positive=False))
        object.__setattr__(self, "velocity_filter", as_bounded(
            self.velocity_filter, "sensing.velocity_filter", 1.0e5, "Hz", positive=False))
        object.__setattr__(self, "latency", as_bounded(
            self.latency, "sensing.latency", 1.0, "s", positive=False))
        s = self.seed
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 0:
            raise InvalidInputError("sensing.seed", f"must be a non-negative integer, got {s!r}")

    def quantum(self, length_per_rad: float) -> float:
        """Cable length per encoder count, m (0: no quantisation)."""
        return 0.0 if self.encoder_counts == 0 else \
            2.0 * np.pi * length_per_rad / self.encoder_counts

    def filter_gain(self, rate: float) -> float:
        """Per-step gain of the twist filter at ``rate`` Hz (1: no filtering)."""
        return 1.0 if self.velocity_filter == 0 else \
            float(1.0 - np.exp(-2.0 * np.pi * self.velocity_filter / rate))

    def delay_steps(self, rate: float) -> int:
        """Latency in control periods at ``rate`` Hz."""
        return int(round(self.latency * rate))

    def describe(self) -> dict[str, Any]:
        """JSON-friendly fields (units: counts per motor revolution, N, s)."""
        return {"ideal_pose": self.ideal_pose, "encoder_counts": self.encoder_counts,
                "tension": self.tension, "tension_noise_N": self.tension_noise,
                "velocity_filter_Hz": self.velocity_filter, "latency_s": self.latency,
                "seed": int(self.seed)}


def quantise(L0: np.ndarray, q: float) -> np.ndarray:
    """Encoder reading of lengths ``L0`` (m) with ``q`` m per count (0: exact)."""
    return L0 if q == 0.0 else np.round(L0 / q) * q


def current_tension(dyn: Any, tau: np.ndarray, speed: np.ndarray, accel: np.ndarray
                    ) -> np.ndarray:
    """Tensions (N) the nominal winch model infers from motor torques ``tau`` (N m), speeds
    (rad/s) and accelerations ``accel`` (rad/s^2): ``kl T - tau_g = tau + tau_f + J accel``
    solved for ``T`` (a disturbance observer; the inertia term removes the drive's own
    torque response, which a static estimate feeds straight back into a tension loop)."""
    from .._tol import FRICTION_SPEED_WIDTH
    s = np.tanh(speed / FRICTION_SPEED_WIDTH)
    eta_b = dyn.efficiency if dyn.backdrive_efficiency is None else dyn.backdrive_efficiency
    rhs = tau + s * (1.0 - dyn.efficiency) * np.maximum(-s * tau, 0.0) + dyn.friction(speed) \
        + dyn.rotor_inertia * accel
    scale = np.where((s > 0.0) & (rhs > 0.0), 1.0 - (1.0 - eta_b) * s * s, 1.0)
    return rhs / (dyn.length_per_rad * scale)


def _rows(p: np.ndarray, R: np.ndarray, exits: np.ndarray, attach: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """Lengths (B, m) and Jacobian rows (B, m, 6) of cables from exits (m, 3)."""
    ra = attach @ np.swapaxes(R, 1, 2)                       # (B, m, 3)
    vec = exits[None] - p[:, None, :] - ra
    L = np.sqrt((vec * vec).sum(axis=2))
    u = vec / L[..., None]
    return L, np.concatenate([-u, -np.cross(ra, u)], axis=2)


def estimate_pose(p: np.ndarray, R: np.ndarray, exits: np.ndarray, attach: np.ndarray,
                  lengths: np.ndarray, iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Newton cable forward kinematics from ``(p, R)`` (B, 3), (B, 3, 3) for measured
    lengths (B, m), m; returns the new estimate (copies)."""
    p, R = p.copy(), R.copy()
    for _ in range(iterations):
        L, J = _rows(p, R, exits, attach)
        JT = np.swapaxes(J, 1, 2)
        step = np.linalg.solve(JT @ J, -(JT @ (L - lengths)[:, :, None]))[:, :, 0]
        p += step[:, :3]
        R = so3_exp(step[:, 3:]) @ R
    return p, R


def estimate_twist(p: np.ndarray, R: np.ndarray, exits: np.ndarray, exit_vel: np.ndarray,
                   attach: np.ndarray, rates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocity of P (B, 3) and angular velocity (B, 3), world, from cable rates (B, m)."""
    _, J = _rows(p, R, exits, attach)
    u = -J[:, :, :3]
    rhs = rates - (u * exit_vel[None]).sum(axis=2)
    JT = np.swapaxes(J, 1, 2)
    tw = np.linalg.solve(JT @ J, (JT @ rhs[:, :, None]))[:, :, 0]
    return tw[:, :3], tw[:, 3:]
