"""Sliding of mobile bases: the ground friction condition as linear constraints on the
cable tensions (the open problem of the FASTKIT paper, §5), in the same exact H-polytope
form as the tension limits (eq. 20) and the tipping constraints (eqs. 21-23).

Model (SI units). Cable ``i`` leaves mobile base ``k`` at its exit point and pulls the
platform with ``t_i u_i`` (``u_i`` the unit vector from the attachment to the exit point),
so it pulls the base with ``-t_i u_i``. With the base weight ``m_k g`` (``g = (0, 0, g_z)``,
``g_z < 0``) the ground must supply the contact force

    ``F_k = -m_k g + sum_i t_i u_i``:   normal ``N_k = -m_k g_z + sum_i t_i u_iz``,
    tangential ``f_k = sum_i t_i (u_ix, u_iy)``.

Coulomb friction with coefficient ``mu_k`` (the same at every wheel and stabiliser foot)
holds the base when ``|f_k| <= mu_k N_k``: summing the contact cones of all contact points
gives exactly this cone for the resultant, whatever the split of the normal force among
the contacts (which tipping, eqs. 21-23, constrains separately). The cone is linearised by
the pyramid of ``P = friction_sides`` faces *inscribed* in it,

    ``d_j . f_k <= mu_k cos(pi / P) N_k``,   ``d_j = (cos(2 pi j / P), sin(2 pi j / P))``,

i.e. ``sum_i t_i (d_j . u_i,xy - mu_k cos(pi / P) u_iz) <= -mu_k cos(pi / P) m_k g_z``:
P rows per base, linear in ``t``. A base accelerating at ``a_k``
(:attr:`~taut.cdpr.Base.acceleration`) feels its d'Alembert force too: ``g`` becomes the
effective gravity ``g_e = g - a_k`` in ``F_k``, so the right-hand side is
``m_k (d_j . g_e,xy - mu_k cos(pi / P) g_e,z)``. Inscribed, so the condition is conservative (it may call
a pose sliding that holds by at most ``1 - cos(pi / P)`` of the friction force) and never
optimistic. ``mu_k = 0`` leaves ``d_j . f_k <= 0`` for all j, i.e. ``f_k = 0``: a
frictionless floor resists no horizontal pull.

Not modelled: slip by rotation about the vertical axis (the friction moment about z that
the cables' yaw moment on the base needs; it depends on how the normal force is shared by
the contacts) and rolling of unbraked wheels (a braked base is assumed).
"""

from __future__ import annotations

import numpy as np

from ..model.robot import CableRobot
from ..._validate import as_array, require_instance

__all__ = ["sliding_rows"]


def _directions(sides: int) -> np.ndarray:
    phi = 2.0 * np.pi * np.arange(sides) / sides
    return np.column_stack([np.cos(phi), np.sin(phi)])


def sliding_rows(robot: CableRobot, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray]:
    """Friction-pyramid constraints ``S t <= s`` on the tensions at a batch of poses.

    Parameters
    ----------
    robot : CableRobot
    unit : (B, m, 3) or (m, 3)
        Cable unit vectors ``u_i`` (attachment to exit), e.g. ``cable_state(...).unit``.

    Returns
    -------
    S : (B, F, m), or (F, m) for one pose's unit vectors (m, 3)
        One row per pyramid face of every mobile base with a friction coefficient (N per N
        of tension; F = 0 when no base has one).
    s : (F,)
        ``m_k (d_j . g_e,xy - mu_k cos(pi / P) g_e,z)``, N (``-mu_k cos(pi / P) m_k g_z``
        for a base at rest).
    base : (F,) int
        Base index of each row.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import cable_state, with_friction
    >>> robot = with_friction(load_cdpr_model("fastkit"), 0.5)
    >>> S, s, base = sliding_rows(robot, cable_state(robot, [0, 0, 1.0]).unit)
    >>> S.shape, base.tolist() == [0] * 8 + [1] * 8
    ((16, 8), True)
    """
    require_instance(robot, CableRobot, "robot")
    unit = as_array(unit, "unit")
    if unit.ndim == 2:
        S1, s1, base1 = sliding_rows(robot, unit[None])
        return S1[0], s1, base1
    unit = as_array(unit, "unit", shape=(None, robot.m, 3))
    B, m, _ = unit.shape
    rows, rhs, owner = [], [], []
    for k, base in enumerate(robot.bases):
        if not base.mobile or base.friction is None:
            continue
        mu_c = base.friction * np.cos(np.pi / base.friction_sides)
        d = _directions(base.friction_sides)                                  # (P, 2)
        on = (robot.cable_base == k).astype(float)                            # (m,)
        coef = np.einsum("pj,bmj->bpm", d, unit[..., :2]) - mu_c * unit[:, None, :, 2]
        rows.append(coef * on[None, None, :])
        ge = base.effective_gravity(robot.gravity)           # weight + d'Alembert force
        rhs.append(base.mass * (d @ ge[:2] - mu_c * ge[2]))
        owner.append(np.full(len(d), k))
    if not rows:
        return np.zeros((B, 0, m)), np.zeros(0), np.zeros(0, dtype=np.intp)
    return np.concatenate(rows, axis=1), np.concatenate(rhs), np.concatenate(owner)
