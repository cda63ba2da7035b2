"""Reference integrator of the cable-robot plant (verification of the fast engines).

The fast engines (:mod:`taut.cdpr.control.plant` and its compiled twin) advance the plant by
semi-implicit Euler with the rotation by the exponential map and an implicit, set-valued
rotor friction. This module integrates the *same model* (the equations of
:mod:`taut.cdpr.control.dynamics` and :mod:`taut.cdpr.control.plant`) by a different method,
written separately, so that the engines can be checked against it:

* classical fourth-order Runge-Kutta (Hairer, Norsett, Wanner, *Solving Ordinary Differential
  Equations I*, Springer 1993, §II.1) at ``inner`` sub-steps per integrator step;
* the attitude as a unit quaternion ``q`` (``q_dot = q (0, w_b) / 2``, renormalised after each
  step) instead of a rotation matrix, the angular velocity in the body frame;
* the rotors' stick-slip friction as a hybrid automaton (Karnopp, "Computer simulation of
  stick-slip friction in mechanical dynamic systems", J. Dyn. Syst. Meas. Control 107(1),
  1985, with the stick state explicit): a sliding rotor feels ``F(w) d + b w`` with its
  direction ``d`` frozen over a step; when its speed changes sign it stops and sticks; a
  stuck rotor stays at rest (``w = 0``, ``L0`` constant) until the other torques on it exceed
  the breakaway torque ``F(0) = tau_s``, and then slides in their direction.

The drives and the controller are discrete-time parts of the system and are shared: the
motor torque is held over each integrator step exactly as in the fast engines (the speed
loop's PI is evaluated at the step's start), and exit points are held over a control period
with their velocity entering the cable damping. So the fast engine and this reference differ
only by the integration of the mechanics: their difference is the fast engine's
discretisation error (first order in the step).

Used by :func:`reference_simulate` and the tests; not a production engine (pure numpy,
~100x slower than the numpy loop).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import InvalidInputError
from .controllers import DESIGN_CONTROL_RATE, Controller
from .plant import EnergyLedger, Plant, PlantState
from .references import Reference
from .results import ControlResult

__all__ = ["reference_simulate"]


def _quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (B, 3, 3) of unit quaternions (B, 4) = (w, x, y, z)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], 1)


def _matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (B, 4) of rotation matrices (B, 3, 3) (Shepperd's method)."""
    out = np.empty((len(R), 4))
    for b, M in enumerate(R):
        tr = np.trace(M)
        cand = np.array([tr, M[0, 0], M[1, 1], M[2, 2]])
        i = int(np.argmax(cand))
        if i == 0:
            s = 2.0 * np.sqrt(1.0 + tr)
            q = [0.25 * s, (M[2, 1] - M[1, 2]) / s, (M[0, 2] - M[2, 0]) / s,
                 (M[1, 0] - M[0, 1]) / s]
        else:
            j, k = (i % 3) + 1, ((i + 1) % 3) + 1
            a, bb, c = i - 1, j - 1, k - 1
            s = 2.0 * np.sqrt(1.0 + M[a, a] - M[bb, bb] - M[c, c])
            q = [0.0] * 4
            q[0] = (M[c, bb] - M[bb, c]) / s
            q[i] = 0.25 * s
            q[j] = (M[bb, a] + M[a, bb]) / s
            q[k] = (M[c, a] + M[a, c]) / s
        out[b] = q
    return out / np.linalg.norm(out, axis=1, keepdims=True)


class RK4Plant(Plant):
    """The plant ``plant`` (same parameters and model errors) integrated by RK4 at
    ``inner`` sub-steps per :meth:`step`, attitude by quaternion, stick-slip by a hybrid
    automaton (see the module docstring)."""

    def __init__(self, plant: Plant, inner: int) -> None:
        self.__dict__.update(plant.__dict__)
        if isinstance(inner, bool) or not isinstance(inner, int) or inner < 1:
            raise InvalidInputError("inner", f"must be a positive integer, got {inner!r}")
        self.inner = inner
        self.stuck = np.ones((plant.B, plant.robot.m), dtype=bool)

    def _forces(self, x: np.ndarray, q: np.ndarray, v: np.ndarray, wb: np.ndarray,
                L0: np.ndarray, w: np.ndarray, exits: np.ndarray, ev: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Tensions (B, m), force (B, 3) and moment about the CoM (B, 3), world, and R."""
        d = self.dyn
        R = _quat_to_matrix(q)
        r = np.einsum("bij,bjm->bim", R, self.attach_c)               # (B, 3, m)
        vec = exits[None] + self.exit_offsets - x[:, :, None] - r
        L = np.linalg.norm(vec, axis=1)
        u = vec / L[:, None, :]
        stretch = L - L0
        k = d.cable_stiffness * stretch
        if d.cable_damping > 0.0:
            om = np.einsum("bij,bj->bi", R, wb)                       # world angular velocity
            va = v[:, :, None] + np.cross(om[:, :, None], r, axis=1)
            rate = np.einsum("bim,bim->bm", u, ev[None] - va) - d.length_per_rad * w
            k = k + d.cable_damping * rate
        T = np.where(stretch > 0.0, np.maximum(k, 0.0), 0.0) / (L0 + self.routing)
        f = u * T[:, None, :]
        return T, f.sum(axis=2) + self.f_ext, np.cross(r, f, axis=1).sum(axis=2) + self.m_ext, R

    def _rhs(self, y: tuple[np.ndarray, ...], tau: np.ndarray, direction: np.ndarray,
             exits: np.ndarray, ev: np.ndarray) -> tuple[np.ndarray, ...]:
        x, q, v, wb, L0, w = y
        d = self.dyn
        T, F, M, R = self._forces(x, q, v, wb, L0, w, exits, ev)
        tb = np.einsum("bji,bj->bi", R, M)                            # body-frame moment
        Iw = np.einsum("bij,bj->bi", self.inertia, wb)
        dwb = np.einsum("bij,bj->bi", self.inertia_inv, tb - np.cross(wb, Iw))
        w0, w1, w2 = wb[:, 0], wb[:, 1], wb[:, 2]
        qw, qx, qy, qz = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
        dq = 0.5 * np.stack([-qx * w0 - qy * w1 - qz * w2, qw * w0 + qy * w2 - qz * w1,
                             qw * w1 + qz * w0 - qx * w2, qw * w2 + qx * w1 - qy * w0], 1)
        kl = d.length_per_rad
        net = kl * T - tau - d.gear_loss(tau, T, w, self.eta, self.eta_b) \
            - self.friction_scale * d.friction_viscous * w
        level = d.friction_level(w, self.friction_scale)
        dw = np.where(self.stuck, 0.0, (net - level * direction) / self.rotor_inertia)
        return (v, dq, F / self.mass[:, None] + self.g, dwb, kl * w, dw)

    def _breakaway(self, y: tuple[np.ndarray, ...], tau: np.ndarray, exits: np.ndarray,
                   ev: np.ndarray) -> np.ndarray:
        """Directions (B, m) of stuck rotors whose torques exceed the breakaway torque (0
        where they hold), and unsticks them."""
        x, q, v, wb, L0, w = y
        d = self.dyn
        T = self._forces(x, q, v, wb, L0, w, exits, ev)[0]
        net = d.length_per_rad * T - tau                   # at rest: no gear loss, no viscous
        go = self.stuck & (np.abs(net) > d.friction_level(0.0, self.friction_scale))
        self.stuck &= ~go
        return np.where(go, np.sign(net), 0.0)

    def step(self, s: PlantState, h: float, exits: np.ndarray, exit_vel: np.ndarray,
             tau: np.ndarray, ledger: EnergyLedger | None = None) -> np.ndarray:
        """Advance by ``h`` s with torques ``tau`` held; returns the tensions at the start.
        (``ledger`` is not supported: the reference books no energy.)"""
        if ledger is not None:
            raise InvalidInputError("ledger", "the reference integrator books no energy")
        ex, ev = exits, exit_vel                         # (3, m) each
        y = (s.xc.copy(), _matrix_to_quat(s.R), s.vc.copy(), s.wb.copy(), s.L0.copy(),
             s.speed.copy())
        T0 = self._forces(*y, ex, ev)[0]
        hs = h / self.inner
        for _ in range(self.inner):
            start = self._breakaway(y, tau, ex, ev)
            direction = np.where(self.stuck, 0.0, np.where(start != 0.0, start,
                                                           np.sign(y[5])))
            k1 = self._rhs(y, tau, direction, ex, ev)
            k2 = self._rhs(_axpy(y, k1, hs / 2), tau, direction, ex, ev)
            k3 = self._rhs(_axpy(y, k2, hs / 2), tau, direction, ex, ev)
            k4 = self._rhs(_axpy(y, k3, hs), tau, direction, ex, ev)
            y = tuple(a + hs / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
                      for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4))
            q = y[1] / np.linalg.norm(y[1], axis=1, keepdims=True)
            w = y[5]
            stop = ~self.stuck & (w * direction <= 0.0)    # the speed changed sign: stick
            self.stuck |= stop
            y = (y[0], q, y[2], y[3], y[4], np.where(self.stuck, 0.0, w))
        s.xc[:], s.vc[:], s.wb[:], s.L0[:], s.speed[:] = y[0], y[2], y[3], y[4], y[5]
        s.R[:] = _quat_to_matrix(y[1])
        return T0


def _axpy(y: tuple[np.ndarray, ...], k: tuple[np.ndarray, ...], a: float
          ) -> tuple[np.ndarray, ...]:
    return tuple(yi + a * ki for yi, ki in zip(y, k))


def reference_simulate(robot: Any, reference: Reference, controller: Controller, *,
                       inner: int = 10, **options: Any) -> ControlResult:
    """:func:`taut.cdpr.simulate` (numpy loop, same options) with the plant integrated by
    :class:`RK4Plant` at ``inner`` RK4 sub-steps per integrator step: the reference the
    fast engines are checked against (tests/cdpr/control/test_plant_physics.py)."""
    from .simulate import DEFAULT_SETTLE, _prepare, _run_python
    names = ("model_errors", "base_motion", "control_rate", "duration", "dynamics",
             "substeps", "external_wrench", "settle", "sensing")
    unknown = set(options) - set(names)
    if unknown:
        raise InvalidInputError(sorted(unknown)[0], "is not an option of simulate")
    defaults: dict[str, Any] = {"control_rate": DESIGN_CONTROL_RATE, "substeps": 1,
                                "settle": DEFAULT_SETTLE}
    kw: dict[str, Any] = {n: options.get(n, defaults.get(n)) for n in names}
    setup = _prepare(robot, reference, controller, kw["model_errors"], kw["base_motion"],
                     kw["control_rate"], kw["duration"], kw["dynamics"], kw["substeps"],
                     kw["external_wrench"], kw["settle"], kw["sensing"])
    setup.plant = RK4Plant(setup.plant, inner)
    return _run_python(setup, controller, None, False)
