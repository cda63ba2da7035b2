"""Compiled control loop (numba), the fast backend of :func:`taut.cdpr.simulate`.

It performs exactly the arithmetic of the numpy backend (:mod:`taut.cdpr.control.plant`,
:mod:`taut.cdpr.control.controllers`, the ``_loop`` of :mod:`taut.cdpr.control.simulate`)
with explicit loops, so one control step costs microseconds instead of ~100 numpy calls; the
tests run both backends on the same problems and require them to agree. Only the two
built-in controllers are compiled (``mode`` 0: velocity, 1: torque); other controllers run
on the numpy backend.

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
         fric_scale: np.ndarray, mass: np.ndarray, inertia: np.ndarray, inertia_inv: np.ndarray,
         attach_c: np.ndarray, com_local: np.ndarray, grav: np.ndarray, ext: np.ndarray,
         xc: np.ndarray, vc: np.ndarray, R: np.ndarray, wb: np.ndarray, L0: np.ndarray,
         speed: np.ndarray, integ: np.ndarray, h: float, substeps: int, lo: np.ndarray,
         hi: np.ndarray, check_every: int, rec: np.ndarray, rec_every: int, summ: np.ndarray,
         k_start: int, diverged: np.ndarray) -> None:
    """Run every plant through every control step (arrays as in the numpy backend).

    Longer than 80 lines on purpose: measurement, both control laws and the monitors are
    one compiled loop nest over (step, plant) that mirrors the numpy backend line by line;
    the plant step is split out (:func:`_plant_step`).

    ``rec`` (T // rec_every, Brec, 12 + 3m) receives x_c, R (row-major), tensions, torques and
    speeds before every ``rec_every``-th step of the first Brec plants; ``summ`` (B, 6)
    accumulates per plant from step ``k_start`` on: max |p - p_ref|, sum |p - p_ref|^2, min and max tension, slack
    steps, torque-saturated steps."""
    n = ctx_L0.shape[0]
    B, m = L0.shape
    EA, damp, kl, eta, tlim, wlim, J = dyn[0], dyn[1], dyn[2], dyn[3], dyn[4], dyn[5], dyn[6]
    fs, fc, fv, wst, weps, Kw, Ki = dyn[7], dyn[8], dyn[9], dyn[10], dyn[11], dyn[12], dyn[13]
    cmd = np.zeros(m)
    tau = np.zeros(m)
    T = np.zeros(m)
    u = np.zeros((3, m))
    r = np.zeros((3, m))
    for k in range(n):
        for b in range(B):
            if diverged[b] >= 0:
                continue
            # -- measurement (ideal pose, encoder lengths) ---------------------------------
            p = np.zeros(3)
            vP = np.zeros(3)
            w = np.zeros(3)
            for i in range(3):
                s = 0.0
                for j in range(3):
                    s += R[b, i, j] * com_local[j]
                p[i] = xc[b, i] - s
            cxw = np.array([com_local[1] * wb[b, 2] - com_local[2] * wb[b, 1],
                            com_local[2] * wb[b, 0] - com_local[0] * wb[b, 2],
                            com_local[0] * wb[b, 1] - com_local[1] * wb[b, 0]])
            for i in range(3):
                for j in range(3):
                    vP[i] += R[b, i, j] * cxw[j]
                    w[i] += R[b, i, j] * wb[b, j]
                vP[i] += vc[b, i]
            e2 = 0.0
            for i in range(3):
                e2 += (p[i] - ref_p[k, i]) ** 2
            if k >= k_start:
                summ[b, 0] = max(summ[b, 0], np.sqrt(e2))
                summ[b, 1] += e2
            # -- controller ----------------------------------------------------------------
            if mode == 0:
                for c in range(m):
                    cmd[c] = (ctx_L0d[k, c] + gains[0] * (ctx_L0[k, c] - (L0[b, c] + len_off[b, c]))) / kl
            else:
                E = np.zeros((3, 3))
                for i in range(3):
                    for j in range(3):
                        for q in range(3):
                            E[i, j] += R_ref[k, i, q] * R[b, j, q]
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
                    cmd[c] = (kl * t - _friction(sw, fs, fc, fv, wst, weps)
                              - J * ctx_L0dd[k, c] / kl
                              + gains[4] * (sw - ctx_L0d[k, c] / kl)) / eta
            # -- plant sub-steps -------------------------------------------------------------
            for sub in range(substeps):
                rec_here = sub == 0 and k % rec_every == 0 and b < rec.shape[1]
                _plant_step(b, mode, cmd, tau, T, u, r, exits[k], exit_vel[k], exit_off, damp,
                            EA, kl, eta, tlim, wlim, J, fs, fc, fv, wst, weps, Kw, Ki,
                            fric_scale, mass, inertia, inertia_inv, attach_c, grav, ext,
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
def _plant_step(b: int, mode: int, cmd: np.ndarray, tau: np.ndarray, T: np.ndarray,
                u: np.ndarray, r: np.ndarray, ex: np.ndarray, ev: np.ndarray,
                exit_off: np.ndarray, damp: float, EA: float, kl: float, eta: float,
                tlim: float, wlim: float, J: float, fs: float, fc: float, fv: float,
                wst: float, weps: float, Kw: float, Ki: float, fric_scale: np.ndarray,
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
                s += R[b, i, j] * attach_c[j, c]
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
            f = (EA * stretch + damp * sdot) / L0[b, c]
            T[c] = max(f, 0.0) if stretch > 0.0 else 0.0
        else:
            T[c] = max(EA * stretch / L0[b, c], 0.0)
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
        fr = fric_scale[b] * _friction(speed[b, c], fs, fc, fv, wst, weps)
        speed[b, c] += h * (kl * T[c] - eta * tau[c] - fr) / J
        L0[b, c] += h * kl * speed[b, c]


@jit
def _rotate(R: np.ndarray, b: int, p0: float, p1: float, p2: float) -> None:
    """``R[b] <- R[b] exp([phi]x)`` (Rodrigues; Taylor series for small angles)."""
    th2 = p0 * p0 + p1 * p1 + p2 * p2
    if th2 < SO3_TAYLOR_SQ:
        a = 1.0 - th2 / 6.0 * (1.0 - th2 / 20.0)
        c2 = 0.5 - th2 / 24.0 * (1.0 - th2 / 30.0)
    else:
        th = np.sqrt(th2)
        a = np.sin(th) / th
        c2 = (1.0 - np.cos(th)) / th2
    K = np.array([[0.0, -p2, p1], [p2, 0.0, -p0], [-p1, p0, 0.0]])
    E = np.eye(3) + a * K + c2 * (K @ K)
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
