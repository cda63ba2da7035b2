"""Compiled control loop (numba), the fast backend of :func:`taut.cdpr.simulate`.

It performs exactly the arithmetic of the numpy backend (:mod:`taut.cdpr.control.plant`,
:mod:`taut.cdpr.control.controllers`, the ``_loop`` of :mod:`taut.cdpr.control.simulate`)
with explicit loops, so one control step costs microseconds instead of ~100 numpy calls; the
tests run both backends on the same problems and require them to agree. The built-in
velocity and torque laws are compiled into the loop (:func:`run`; ``mode`` 0: velocity, 1:
torque); every other controller (computed torque, custom ones) runs in Python once per
control step between two compiled calls, :func:`measure` (the sensing, with the pose
estimate of :class:`taut.cdpr.Sensing`, :func:`_estimate`) and :func:`plant_steps` (the
plant's sub-steps). :func:`run` calls the same :func:`_measure_plant` and
:func:`_plant_step`, so both paths compute the same numbers.

Compiled by :func:`taut._jit.jit`, the package's one numba set-up (on-disk cache, numpy
error model); without numba the functions stay plain Python and the simulation picks the
numpy backend. Functions compile on first call.
"""

from __future__ import annotations

import numpy as np

from ..._jit import jit
from .._tol import EVENT_TENSION_TOL, SO3_TAYLOR_SQ


@jit
def _friction(w: float, fs: float, fc: float, fv: float, ws: float, weps: float) -> float:
    level = fc + (fs - fc) * np.exp(-(w / ws) ** 2)
    return level * np.tanh(w / weps) + fv * w


@jit
def run(mode: int, gains: np.ndarray, dyn: np.ndarray, ctx_L0: np.ndarray,
        ctx_L0d: np.ndarray, ctx_L0dd: np.ndarray, ref_p: np.ndarray, ref_v: np.ndarray,
        R_ref: np.ndarray, t_ref: np.ndarray, W_pinv: np.ndarray, comT: np.ndarray,
        inertia_ref: np.ndarray, mass_nom: float, t_min: np.ndarray, t_max: np.ndarray,
        exits: np.ndarray, exit_vel: np.ndarray, exit_off: np.ndarray, len_off: np.ndarray,
        winch: np.ndarray, mass: np.ndarray, inertia: np.ndarray, inertia_inv: np.ndarray,
        attach_c: np.ndarray, com_local: np.ndarray, grav: np.ndarray, ext: np.ndarray,
        xc: np.ndarray, vc: np.ndarray, R: np.ndarray, wb: np.ndarray, L0: np.ndarray,
        speed: np.ndarray, integ: np.ndarray, h: float, substeps: int, lo: np.ndarray,
        hi: np.ndarray, check_every: int, rec: np.ndarray, rec_every: int, summ: np.ndarray,
        k_start: int, diverged: np.ndarray, sens: np.ndarray, noise: np.ndarray,
        attach_P: np.ndarray, est_p: np.ndarray, est_R: np.ndarray, est_v: np.ndarray,
        est_w: np.ndarray, T_last: np.ndarray, tau_last: np.ndarray, buf: np.ndarray,
        speed_last: np.ndarray, T_est: np.ndarray, dt: float) -> None:
    """Run every plant through every control step (arrays as in the numpy backend).

    Longer than 80 lines on purpose: both control laws and the monitors are one compiled
    loop nest over (step, plant) that mirrors the numpy backend line by line; the
    measurement and the plant step are split out (:func:`_measure_plant`,
    :func:`_plant_step`) and shared with the path of controllers that run in Python.

    ``com_local`` (B, 3) and ``attach_c`` (B, 3, m) are per plant (payload mass errors move
    the centre of mass). ``winch`` (5, B, m) holds the plant's forward and back-drive efficiencies, friction
    scales, rotor inertias and routing lengths (m); ``dyn[15:15 + m]`` the nominal routing
    lengths (the estimator's); ``dyn[4]`` is the peak torque the drives saturate at; ``sens`` = (ideal pose 0/1, encoder quantum m, tension
    source 0 none / 1 current / 2 load cell, twist filter gain, delay steps, FK iterations
    per step, FK iterations at the first step); ``buf`` (delay + 1, B, m) the commands in
    flight. ``rec`` (T // rec_every, Brec, 12 + 3m) receives x_c, R (row-major), tensions,
    torques and speeds before every ``rec_every``-th step of the first Brec plants; ``summ``
    (B, 6) accumulates per plant from step ``k_start`` on: max |p - p_ref|, sum
    |p - p_ref|^2, min and max tension, slack steps, torque-saturated steps."""
    n = ctx_L0.shape[0]
    B, m = L0.shape
    EA, damp, kl, eta, tlim, wlim, J = dyn[0], dyn[1], dyn[2], dyn[3], dyn[4], dyn[5], dyn[6]
    fs, fc, fv, wst, weps, Kw, Ki = dyn[7], dyn[8], dyn[9], dyn[10], dyn[11], dyn[12], dyn[13]
    eta_b = dyn[14]
    delay = int(sens[4])
    nb = delay + 1
    cmd = np.zeros(m)
    tau = np.zeros(m)
    T = np.zeros(m)
    u = np.zeros((3, m))
    r = np.zeros((3, m))
    Lm = np.zeros(m)
    Tm = np.zeros(m)
    Jr = np.zeros((m, 6))
    res = np.zeros(m)
    A6 = np.zeros((6, 6))
    g6 = np.zeros(6)
    x6 = np.zeros(6)
    p = np.zeros(3)
    vP = np.zeros(3)
    w = np.zeros(3)
    Rm = np.empty((3, 3))
    for k in range(n):
        for b in range(B):
            if diverged[b] >= 0:
                continue
            # -- measurement: true pose (tracking error), encoders, tension ----------------
            e2 = _measure_plant(b, k, sens, dyn, xc, vc, R, wb, com_local, L0, len_off, speed,
                                noise, ref_p, ref_v, t_ref, exits, exit_vel, attach_P, T_last,
                                tau_last, speed_last, T_est, est_p, est_R, est_v, est_w, dt,
                                p, vP, w, Rm, Lm, Tm, Jr, res, A6, g6, x6)
            if k >= k_start:
                summ[b, 0] = max(summ[b, 0], np.sqrt(e2))
                summ[b, 1] += e2
            # -- controller ----------------------------------------------------------------
            if mode == 0:
                for c in range(m):
                    rate = ctx_L0d[k, c] + gains[0] * (ctx_L0[k, c] - Lm[c])
                    if gains[1] > 0.0:
                        rate += gains[1] * (Tm[c] - t_ref[k, c]) * ctx_L0[k, c] / EA
                    cmd[c] = rate / kl
            else:
                E = np.zeros((3, 3))
                for i in range(3):
                    for j in range(3):
                        for q in range(3):
                            E[i, j] += R_ref[k, i, q] * Rm[j, q]
                er = 0.5 * np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
                a = np.zeros(3)
                al = np.zeros(3)
                for i in range(3):
                    a[i] = gains[0] * (ref_p[k, i] - p[i]) + gains[1] * (ref_v[k, i] - vP[i])
                    al[i] = gains[2] * er[i] + gains[3] * (ref_v[k, 3 + i] - w[i])
                wr = np.zeros(6)
                for i in range(3):
                    s = 0.0
                    for j in range(3):
                        s += al[j] * comT[k, j, i]
                    wr[i] = mass_nom * (a[i] - s)
                for i in range(3):
                    s = 0.0
                    for j in range(3):
                        s += al[j] * inertia_ref[k, i, j] + wr[j] * comT[k, j, i]
                    wr[3 + i] = s
                for c in range(m):
                    t = t_ref[k, c]
                    for i in range(6):
                        t += W_pinv[k, c, i] * wr[i]
                    t = min(max(t, t_min[c]), t_max[c])
                    sw = speed[b, c]
                    load = (kl * t - _friction(sw, fs, fc, fv, wst, weps)
                            - J * ctx_L0dd[k, c] / kl + gains[4] * (sw - ctx_L0d[k, c] / kl))
                    cmd[c] = _holding_torque(load, kl * t, sw, eta, eta_b, weps)
            # -- commands in flight (latency) ------------------------------------------------
            for c in range(m):
                if k == 0:
                    for j in range(nb):
                        buf[j, b, c] = cmd[c]
                else:
                    buf[k % nb, b, c] = cmd[c]
            for c in range(m):
                cmd[c] = buf[(k - delay) % nb if k >= delay else 0, b, c]
            # -- plant sub-steps -------------------------------------------------------------
            for sub in range(substeps):
                rec_here = sub == 0 and k % rec_every == 0 and b < rec.shape[1]
                _plant_step(b, mode, cmd, tau, T, u, r, exits[k], exit_vel[k], exit_off, damp,
                            EA, kl, tlim, wlim, fs, fc, fv, wst, weps, Kw, Ki,
                            winch, mass, inertia, inertia_inv, attach_c, grav, ext,
                            xc, vc, R, wb, L0, speed, integ, h, rec, k // rec_every, rec_here)
                if sub == 0 and k >= k_start:
                    slack = False
                    sat = False
                    for c in range(m):
                        summ[b, 2] = min(summ[b, 2], T[c])
                        summ[b, 3] = max(summ[b, 3], T[c])
                        if T[c] < t_min[c] - EVENT_TENSION_TOL:
                            slack = True
                        if abs(tau[c]) >= tlim:
                            sat = True
                    summ[b, 4] += slack
                    summ[b, 5] += sat
            for c in range(m):
                T_last[b, c] = T[c]
                tau_last[b, c] = tau[c]
            if (k % check_every == check_every - 1) or k == n - 1:
                ok = True
                for i in range(3):
                    if not (xc[b, i] > lo[i] and xc[b, i] < hi[i]):
                        ok = False
                for c in range(m):
                    if not np.isfinite(L0[b, c]):
                        ok = False
                if not ok:
                    diverged[b] = k


@jit
def _measure_plant(b: int, k: int, sens: np.ndarray, dyn: np.ndarray, xc: np.ndarray,
                   vc: np.ndarray, R: np.ndarray, wb: np.ndarray, com_local: np.ndarray,
                   L0: np.ndarray, len_off: np.ndarray, speed: np.ndarray, noise: np.ndarray,
                   ref_p: np.ndarray, ref_v: np.ndarray, t_ref: np.ndarray, exits: np.ndarray,
                   exit_vel: np.ndarray, attach_P: np.ndarray, T_last: np.ndarray,
                   tau_last: np.ndarray, speed_last: np.ndarray, T_est: np.ndarray,
                   est_p: np.ndarray, est_R: np.ndarray, est_v: np.ndarray, est_w: np.ndarray,
                   dt: float, p: np.ndarray, vP: np.ndarray, w: np.ndarray, Rm: np.ndarray,
                   Lm: np.ndarray, Tm: np.ndarray, Jr: np.ndarray, res: np.ndarray,
                   A6: np.ndarray, g6: np.ndarray, x6: np.ndarray) -> float:
    """What the controller of plant ``b`` sees at step ``k`` (see ``_measure`` of
    :mod:`taut.cdpr.control.simulate`): writes ``p``, ``vP``, ``w`` (3,), ``Rm`` (3, 3),
    ``Lm``, ``Tm`` (m,) and updates the sensing state (``speed_last``, ``T_est``,
    ``est_*``); returns the squared distance of the *true* P from the reference, m^2.
    ``sens`` and ``dyn`` as in :func:`run`."""
    m = L0.shape[1]
    EA, kl, eta, J, eta_b = dyn[0], dyn[2], dyn[3], dyn[6], dyn[14]
    fs, fc, fv, wst, weps = dyn[7], dyn[8], dyn[9], dyn[10], dyn[11]
    ideal, quantum, tsrc, fgain = sens[0] > 0.5, sens[1], int(sens[2]), sens[3]
    it_step, it_first = int(sens[5]), int(sens[6])
    for i in range(3):
        vP[i] = 0.0
        w[i] = 0.0
    for i in range(3):
        s = 0.0
        for j in range(3):
            s += R[b, i, j] * com_local[b, j]
        p[i] = xc[b, i] - s
    c0, c1, c2 = com_local[b, 0], com_local[b, 1], com_local[b, 2]
    cxw = np.array([c1 * wb[b, 2] - c2 * wb[b, 1], c2 * wb[b, 0] - c0 * wb[b, 2],
                    c0 * wb[b, 1] - c1 * wb[b, 0]])
    for i in range(3):
        for j in range(3):
            vP[i] += R[b, i, j] * cxw[j]
            w[i] += R[b, i, j] * wb[b, j]
        vP[i] += vc[b, i]
    e2 = 0.0
    for i in range(3):
        e2 += (p[i] - ref_p[k, i]) ** 2
    kn = k % noise.shape[0]
    bn = b % noise.shape[1]
    for c in range(m):
        x = L0[b, c] + len_off[b, c]
        Lm[c] = x if quantum == 0.0 else np.round(x / quantum) * quantum
        if tsrc == 2:
            Tm[c] = T_last[b, c] + noise[kn, bn, c]
        elif tsrc == 1:
            acc = (speed[b, c] - speed_last[b, c]) / dt if k > 0 else 0.0
            raw = _current_tension(tau_last[b, c], speed[b, c], acc, kl, J, eta,
                                   eta_b, fs, fc, fv, wst, weps)
            T_est[b, c] += (1.0 if k == 0 else fgain) * (raw - T_est[b, c])
            Tm[c] = T_est[b, c] + noise[kn, bn, c]
        else:
            Tm[c] = np.nan
    for c in range(m):
        speed_last[b, c] = speed[b, c]
    if ideal:
        for i in range(3):
            for j in range(3):
                Rm[i, j] = R[b, i, j]
    else:
        _estimate(b, k, it_first if k == 0 else it_step, 1.0 if k == 0 else fgain,
                  Lm, Tm, tsrc == 2, t_ref[k], EA, dyn[15:], kl, speed, exits[k],
                  exit_vel[k], attach_P, ref_v[k], est_p, est_R, est_v, est_w,
                  Jr, res, A6, g6, x6)
        for i in range(3):
            p[i] = est_p[b, i]
            vP[i] = ref_v[k, i] + est_v[b, i]
            w[i] = ref_v[k, 3 + i] + est_w[b, i]
            for j in range(3):
                Rm[i, j] = est_R[b, i, j]
    return e2


@jit
def measure(k: int, sens: np.ndarray, dyn: np.ndarray, xc: np.ndarray, vc: np.ndarray,
            R: np.ndarray, wb: np.ndarray, com_local: np.ndarray, L0: np.ndarray,
            len_off: np.ndarray, speed: np.ndarray, noise: np.ndarray, ref_p: np.ndarray,
            ref_v: np.ndarray, t_ref: np.ndarray, exits: np.ndarray, exit_vel: np.ndarray,
            attach_P: np.ndarray, T_last: np.ndarray, tau_last: np.ndarray,
            speed_last: np.ndarray, T_est: np.ndarray, est_p: np.ndarray, est_R: np.ndarray,
            est_v: np.ndarray, est_w: np.ndarray, dt: float, P: np.ndarray, Rm: np.ndarray,
            V: np.ndarray, W: np.ndarray, Lm: np.ndarray, Tm: np.ndarray) -> None:
    """The measurements of every plant at step ``k`` for a controller that runs in Python
    (the hybrid engine): :func:`_measure_plant` per plant into ``P``, ``V``, ``W`` (B, 3),
    ``Rm`` (B, 3, 3), ``Lm``, ``Tm`` (B, m)."""
    B, m = L0.shape
    Jr = np.zeros((m, 6))
    res = np.zeros(m)
    A6 = np.zeros((6, 6))
    g6 = np.zeros(6)
    x6 = np.zeros(6)
    for b in range(B):
        _measure_plant(b, k, sens, dyn, xc, vc, R, wb, com_local, L0, len_off, speed, noise,
                       ref_p, ref_v, t_ref, exits, exit_vel, attach_P, T_last, tau_last,
                       speed_last, T_est, est_p, est_R, est_v, est_w, dt, P[b], V[b], W[b],
                       Rm[b], Lm[b], Tm[b], Jr, res, A6, g6, x6)


@jit
def plant_steps(mode: int, cmd: np.ndarray, dyn: np.ndarray, exits: np.ndarray,
                exit_vel: np.ndarray, exit_off: np.ndarray, winch: np.ndarray,
                mass: np.ndarray, inertia: np.ndarray, inertia_inv: np.ndarray,
                attach_c: np.ndarray, grav: np.ndarray, ext: np.ndarray, xc: np.ndarray,
                vc: np.ndarray, R: np.ndarray, wb: np.ndarray, L0: np.ndarray,
                speed: np.ndarray, integ: np.ndarray, h: float, substeps: int,
                T_first: np.ndarray, tau_first: np.ndarray, T_last: np.ndarray,
                tau_last: np.ndarray) -> None:
    """One control period of every plant under the commands ``cmd`` (B, m) of a controller
    that runs in Python (the compiled plant of the hybrid engine, see
    :func:`taut.cdpr.simulate`): ``substeps`` calls of :func:`_plant_step` per plant.

    ``mode`` 1: ``cmd`` are motor torques, N m; 0: motor speed set-points, rad/s. ``dyn`` and
    ``winch`` as in :func:`run`; ``exits``, ``exit_vel`` (3, m) at this step. Writes the
    tensions (N) and motor torques (N m) of the first sub-step into ``T_first``,
    ``tau_first`` and of the last into ``T_last``, ``tau_last`` (each (B, m))."""
    B, m = L0.shape
    EA, damp, kl, tlim, wlim = dyn[0], dyn[1], dyn[2], dyn[4], dyn[5]
    fs, fc, fv, wst, weps, Kw, Ki = dyn[7], dyn[8], dyn[9], dyn[10], dyn[11], dyn[12], dyn[13]
    c_b = np.zeros(m)
    tau = np.zeros(m)
    T = np.zeros(m)
    u = np.zeros((3, m))
    r = np.zeros((3, m))
    rec = np.zeros((1, 1, 12 + 3 * m))
    for b in range(B):
        for c in range(m):
            c_b[c] = cmd[b, c]
        for sub in range(substeps):
            _plant_step(b, mode, c_b, tau, T, u, r, exits, exit_vel, exit_off, damp,
                        EA, kl, tlim, wlim, fs, fc, fv, wst, weps, Kw, Ki,
                        winch, mass, inertia, inertia_inv, attach_c, grav, ext,
                        xc, vc, R, wb, L0, speed, integ, h, rec, 0, False)
            if sub == 0:
                for c in range(m):
                    T_first[b, c] = T[c]
                    tau_first[b, c] = tau[c]
        for c in range(m):
            T_last[b, c] = T[c]
            tau_last[b, c] = tau[c]


@jit
def _gear_loss(tau: float, load: float, w: float, eta: float, eta_b: float,
               weps: float) -> float:
    """Gearbox loss torque (see :meth:`taut.cdpr.DynamicsModel.gear_loss`); ``load = kl T``."""
    s = np.tanh(w / weps)
    return s * ((1.0 - eta) * max(-s * tau, 0.0) + (1.0 - eta_b) * max(s * load, 0.0))


@jit
def _holding_torque(net: float, load: float, w: float, eta: float, eta_b: float,
                    weps: float) -> float:
    """``tau`` with ``tau + tau_g = net`` (see :meth:`taut.cdpr.DynamicsModel.holding_torque`)."""
    s = np.tanh(w / weps)
    z = net - (1.0 - eta_b) * s * max(s * load, 0.0)
    return z / (1.0 - (1.0 - eta) * s * s) if z * s < 0.0 else z


@jit
def _current_tension(tau: float, w: float, acc: float, kl: float, J: float, eta: float,
                     eta_b: float, fs: float, fc: float, fv: float, wst: float,
                     weps: float) -> float:
    """Tension from the motor torque (see :func:`taut.cdpr.control.sensing.current_tension`)."""
    s = np.tanh(w / weps)
    rhs = tau + s * (1.0 - eta) * max(-s * tau, 0.0) + _friction(w, fs, fc, fv, wst, weps) \
        + J * acc
    scale = 1.0 - (1.0 - eta_b) * s * s if (s > 0.0 and rhs > 0.0) else 1.0
    return rhs / (kl * scale)


@jit
def _estimate(b: int, k: int, iterations: int, gain: float, Lm: np.ndarray, Tm: np.ndarray,
              load_cell: bool, t_ref: np.ndarray, EA: float, rho: np.ndarray, kl: float,
              speed: np.ndarray,
              ex: np.ndarray, ev: np.ndarray, attach_P: np.ndarray, vref: np.ndarray,
              est_p: np.ndarray, est_R: np.ndarray, est_v: np.ndarray, est_w: np.ndarray,
              Jr: np.ndarray, res: np.ndarray, A: np.ndarray, g: np.ndarray, x: np.ndarray
              ) -> None:
    """Pose (Gauss-Newton cable FK) and twist estimate of plant ``b`` from encoder lengths
    (see :mod:`taut.cdpr.control.sensing`); updates ``est_*[b]`` in place (``est_v``,
    ``est_w``: the filtered deviation from the reference twist ``vref``). ``Jr`` (m, 6),
    ``res`` (m,), ``A`` (6, 6), ``g``, ``x`` (6,) are scratch (no allocation per step)."""
    m = Lm.shape[0]
    for it in range(iterations + 1):
        for c in range(m):
            r0 = est_R[b, 0, 0] * attach_P[0, c] + est_R[b, 0, 1] * attach_P[1, c] \
                + est_R[b, 0, 2] * attach_P[2, c]
            r1 = est_R[b, 1, 0] * attach_P[0, c] + est_R[b, 1, 1] * attach_P[1, c] \
                + est_R[b, 1, 2] * attach_P[2, c]
            r2 = est_R[b, 2, 0] * attach_P[0, c] + est_R[b, 2, 1] * attach_P[1, c] \
                + est_R[b, 2, 2] * attach_P[2, c]
            v0 = ex[0, c] - est_p[b, 0] - r0
            v1 = ex[1, c] - est_p[b, 1] - r1
            v2 = ex[2, c] - est_p[b, 2] - r2
            L = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            u0, u1, u2 = v0 / L, v1 / L, v2 / L
            known = Tm[c] if load_cell else t_ref[c]
            res[c] = L - (Lm[c] + known * (Lm[c] + rho[c]) / EA)
            Jr[c, 0], Jr[c, 1], Jr[c, 2] = -u0, -u1, -u2
            Jr[c, 3] = -(r1 * u2 - r2 * u1)
            Jr[c, 4] = -(r2 * u0 - r0 * u2)
            Jr[c, 5] = -(r0 * u1 - r1 * u0)
        for i in range(6):
            for j in range(6):
                s = 0.0
                for c in range(m):
                    s += Jr[c, i] * Jr[c, j]
                A[i, j] = s
        if it == iterations:
            # twist: rows against the cable rates minus the exits' motion
            for i in range(6):
                s = 0.0
                for c in range(m):
                    s += Jr[c, i] * (kl * speed[b, c] + Jr[c, 0] * ev[0, c]
                                     + Jr[c, 1] * ev[1, c] + Jr[c, 2] * ev[2, c])
                g[i] = s
            _spd_solve6(A, g, x)
            for i in range(3):
                est_v[b, i] += gain * (x[i] - vref[i] - est_v[b, i])
                est_w[b, i] += gain * (x[3 + i] - vref[3 + i] - est_w[b, i])
            break
        for i in range(6):
            s = 0.0
            for c in range(m):
                s -= Jr[c, i] * res[c]
            g[i] = s
        _spd_solve6(A, g, x)
        for i in range(3):
            est_p[b, i] += x[i]
        _rotate_left(est_R, b, x[3], x[4], x[5])


@jit
def _spd_solve6(A: np.ndarray, g: np.ndarray, x: np.ndarray) -> None:
    """``x = A^-1 g`` for a symmetric positive definite 6 x 6 ``A`` by Cholesky, in place
    (``A`` is overwritten by its factor)."""
    for j in range(6):
        d = A[j, j]
        for q in range(j):
            d -= A[j, q] * A[j, q]
        d = np.sqrt(d)
        A[j, j] = d
        for i in range(j + 1, 6):
            s = A[i, j]
            for q in range(j):
                s -= A[i, q] * A[j, q]
            A[i, j] = s / d
    for i in range(6):
        s = g[i]
        for q in range(i):
            s -= A[i, q] * x[q]
        x[i] = s / A[i, i]
    for i in range(5, -1, -1):
        s = x[i]
        for q in range(i + 1, 6):
            s -= A[q, i] * x[q]
        x[i] = s / A[i, i]


@jit
def _plant_step(b: int, mode: int, cmd: np.ndarray, tau: np.ndarray, T: np.ndarray,
                u: np.ndarray, r: np.ndarray, ex: np.ndarray, ev: np.ndarray,
                exit_off: np.ndarray, damp: float, EA: float, kl: float,
                tlim: float, wlim: float, fs: float, fc: float, fv: float,
                wst: float, weps: float, Kw: float, Ki: float, winch: np.ndarray,
                mass: np.ndarray, inertia: np.ndarray, inertia_inv: np.ndarray,
                attach_c: np.ndarray, grav: np.ndarray, ext: np.ndarray, xc: np.ndarray,
                vc: np.ndarray, R: np.ndarray, wb: np.ndarray, L0: np.ndarray,
                speed: np.ndarray, integ: np.ndarray, h: float, rec: np.ndarray, k: int,
                first: bool) -> None:
    """One semi-implicit Euler step of plant ``b`` (see :meth:`taut.cdpr.control.plant.Plant.step`).
    Long because it is written out in scalars for numba (cable forces, drive, rigid body,
    winches); each block mirrors one line of the numpy version."""
    m = L0.shape[1]
    w = np.zeros(3)
    for i in range(3):
        for j in range(3):
            w[i] += R[b, i, j] * wb[b, j]
    F = np.zeros(3)
    Mw = np.zeros(3)
    for c in range(m):
        vec = np.zeros(3)
        for i in range(3):
            s = 0.0
            for j in range(3):
                s += R[b, i, j] * attach_c[b, j, c]
            r[i, c] = s
            vec[i] = ex[i, c] + exit_off[b, i, c] - xc[b, i] - s
        L = np.sqrt(vec[0] ** 2 + vec[1] ** 2 + vec[2] ** 2)
        for i in range(3):
            u[i, c] = vec[i] / L
        stretch = L - L0[b, c]
        if damp > 0.0:
            va = np.array([vc[b, 0] + w[1] * r[2, c] - w[2] * r[1, c],
                           vc[b, 1] + w[2] * r[0, c] - w[0] * r[2, c],
                           vc[b, 2] + w[0] * r[1, c] - w[1] * r[0, c]])
            sdot = -kl * speed[b, c]
            for i in range(3):
                sdot += u[i, c] * (ev[i, c] - va[i])
            f = (EA * stretch + damp * sdot) / (L0[b, c] + winch[4, b, c])
            T[c] = max(f, 0.0) if stretch > 0.0 else 0.0
        else:
            T[c] = max(EA * stretch / (L0[b, c] + winch[4, b, c]), 0.0)
        for i in range(3):
            F[i] += T[c] * u[i, c]
        Mw[0] += T[c] * (r[1, c] * u[2, c] - r[2, c] * u[1, c])
        Mw[1] += T[c] * (r[2, c] * u[0, c] - r[0, c] * u[2, c])
        Mw[2] += T[c] * (r[0, c] * u[1, c] - r[1, c] * u[0, c])
    # motor torques
    for c in range(m):
        if mode == 1:
            tau[c] = min(max(cmd[c], -tlim), tlim)
        else:
            err = speed[b, c] - min(max(cmd[c], -wlim), wlim)
            tau[c] = min(max(Kw * err + integ[b, c], -tlim), tlim)
            integ[b, c] = min(max(integ[b, c] + h * Ki * err, -tlim), tlim)
    if first:
        for i in range(3):
            rec[k, b, i] = xc[b, i]
            for j in range(3):
                rec[k, b, 3 + 3 * i + j] = R[b, i, j]
        for c in range(m):
            rec[k, b, 12 + c] = T[c]
            rec[k, b, 12 + m + c] = tau[c]
            rec[k, b, 12 + 2 * m + c] = speed[b, c]
    # platform: body-frame moment about the CoM, gyroscopic term
    tb = np.zeros(3)
    for i in range(3):
        for j in range(3):
            tb[i] += R[b, j, i] * (Mw[j] + ext[3 + j])
    Iw = np.zeros(3)
    for i in range(3):
        for j in range(3):
            Iw[i] += inertia[b, i, j] * wb[b, j]
    rhs = np.array([tb[0] - (wb[b, 1] * Iw[2] - wb[b, 2] * Iw[1]),
                    tb[1] - (wb[b, 2] * Iw[0] - wb[b, 0] * Iw[2]),
                    tb[2] - (wb[b, 0] * Iw[1] - wb[b, 1] * Iw[0])])
    for i in range(3):
        vc[b, i] += h * ((F[i] + ext[i]) / mass[b] + grav[i])
    dw = np.zeros(3)
    for i in range(3):
        for j in range(3):
            dw[i] += inertia_inv[b, i, j] * rhs[j]
    for i in range(3):
        wb[b, i] += h * dw[i]
        xc[b, i] += h * vc[b, i]
    _rotate(R, b, h * wb[b, 0], h * wb[b, 1], h * wb[b, 2])
    for c in range(m):
        sw = speed[b, c]
        gl = _gear_loss(tau[c], kl * T[c], sw, winch[0, b, c], winch[1, b, c], weps)
        # implicit friction with stick (DynamicsModel.friction_step)
        Jc, sc = winch[3, b, c], winch[2, b, c]
        z = Jc * sw + h * (kl * T[c] - tau[c] - gl)
        F = sc * (fc + (fs - fc) * np.exp(-(sw / wst) ** 2))
        f = min(max(z / h, -F), F)
        speed[b, c] = (z - h * f) / (Jc + h * sc * fv)
        L0[b, c] += h * kl * speed[b, c]


@jit
def _rotate_left(R: np.ndarray, b: int, p0: float, p1: float, p2: float) -> None:
    """``R[b] <- exp([phi]x) R[b]``."""
    E = _expm(p0, p1, p2)
    for j in range(3):
        c0, c1, c2 = R[b, 0, j], R[b, 1, j], R[b, 2, j]
        for i in range(3):
            R[b, i, j] = E[i, 0] * c0 + E[i, 1] * c1 + E[i, 2] * c2


@jit
def _expm(p0: float, p1: float, p2: float) -> np.ndarray:
    """``exp([phi]x)`` (Rodrigues; Taylor series for small angles)."""
    th2 = p0 * p0 + p1 * p1 + p2 * p2
    if th2 < SO3_TAYLOR_SQ:
        a = 1.0 - th2 / 6.0 * (1.0 - th2 / 20.0)
        c2 = 0.5 - th2 / 24.0 * (1.0 - th2 / 30.0)
    else:
        th = np.sqrt(th2)
        a = np.sin(th) / th
        c2 = (1.0 - np.cos(th)) / th2
    K = np.array([[0.0, -p2, p1], [p2, 0.0, -p0], [-p1, p0, 0.0]])
    return np.eye(3) + a * K + c2 * (K @ K)


@jit
def _rotate(R: np.ndarray, b: int, p0: float, p1: float, p2: float) -> None:
    """``R[b] <- R[b] exp([phi]x)``."""
    E = _expm(p0, p1, p2)
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            s = 0.0
            for q in range(3):
                s += R[b, i, q] * E[q, j]
            out[i, j] = s
    for i in range(3):
        for j in range(3):
            R[b, i, j] = out[i, j]
