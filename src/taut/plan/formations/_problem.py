"""The nonlinear program of the optimal formation (planning paper Sec. IV-A, eq. 15, as
rebuilt in :mod:`taut.plan.formations.optimal`): the decision vector, the cost of eqs. (11)-(14),
the constraints (15b)-(15c) in normalised units (lengths divided by the sheet size), and
the nominal inverse-kinematics start.

The solve (SciPy SLSQP), its fallback and the forward-kinematics acceptance of the result
are in :func:`taut.plan.formations.optimal.optimal_formation`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import TautError
from ...sheet import ik_constraints, inverse_kinematics
from .. import _tol
from ..world import Team

__all__ = ["CostWeights", "COMPACT", "MIN_DEPTH_FRACTION", "MIN_SHARE"]

#: The object hangs at least this fraction of the holding height below the hands (a flat
#: sheet would need unbounded tensions).
MIN_DEPTH_FRACTION = 0.05
#: Smallest load share a cable may carry in a planned formation.
MIN_SHARE = 0.02


@dataclass(frozen=True)
class CostWeights:
    """Weights of the rebuilt costs (eqs. 12-14; dimensionless)."""

    transport: float = 1.0        # alpha_t
    load_share: float = 1.0       # beta_t
    passable: float = 1.0         # alpha_p
    crossing_height: float = 10.0  # alpha_c
    crossing_gap: float = 0.1     # beta_c


#: Weights of the compact (bypassing) formation: size dominates.
COMPACT = CostWeights(transport=0.1, load_share=0.1, passable=10.0, crossing_height=0.0,
                      crossing_gap=0.0)


@dataclass(frozen=True)
class _Decision:
    """Layout of the decision vector of eq. (15), in sheet-size units: contact
    :math:`\\mathbf{v}_o` (2), :math:`z_o` (1), angles :math:`\\theta_i` (N), shares
    :math:`w_i` (N), auxiliary radius :math:`\\bar R` (1)."""

    n: int

    @property
    def length(self) -> int:
        return 3 + 2 * self.n + 1

    def split(self, z: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray, float]:
        """(contact, z_o, angles, weights, R_bar) of ``z``."""
        n = self.n
        return z[:2], float(z[2]), z[3:3 + n], z[3 + n:3 + 2 * n], float(z[-1])

    def pack(self, contact: np.ndarray, zo: float, angles: np.ndarray, weights: np.ndarray,
             radius: float) -> np.ndarray:
        return np.concatenate([contact, [zo], angles, weights, [radius]])


@dataclass(frozen=True)
class _Problem:
    """Normalised data of eq. (15) for one team and request (lengths / sheet size)."""

    V: np.ndarray            # sheet vertices (N, 2)
    zr: float                # holding height
    z_lo: float              # lowest admissible object height (15b)
    z_hi: float              # highest (MIN_DEPTH_FRACTION below the hands)
    sep: float               # least robot gap (robots apart, obstacle through; 15b)
    ds: float                # side safety
    w_ref: float             # free-space width normalising eq. (13)
    r_max: float             # bound on the auxiliary radius (eq. 13 as a constraint)
    vd2: np.ndarray          # squared admissible robot distances per pair (sheet margin)
    rho0: np.ndarray         # nominal radial distances (IK at the centroid)
    crossing: bool
    weights: CostWeights
    dec: _Decision
    narrow: bool = False     # R_bar bounds |y_i| (half-width), not the radius

    @property
    def pairs(self) -> tuple[np.ndarray, np.ndarray]:
        return np.triu_indices(self.dec.n, 1)

    def geometry(self, z: np.ndarray):
        """(contact, z_o, angles, weights, R_bar, squared cable-projection lengths
        :math:`l_i^2`, hand drop :math:`z_r - z_o`, radial distances :math:`\\rho_i`,
        robot positions (N, 2)) of decision vector ``z`` (eq. 10)."""
        vo, zo, th, w, Rb = self.dec.split(z)
        l2 = np.sum((self.V - vo) ** 2, axis=1)
        d = self.zr - zo
        rho = np.sqrt(np.maximum(l2 - d * d, _tol.SQUARE_FLOOR))
        r = rho[:, None] * np.column_stack([np.cos(th), np.sin(th)])
        return vo, zo, th, w, Rb, l2, d, rho, r

    def cost(self, z: np.ndarray) -> float:
        """:math:`J = J_t + J_p + J_c` (eqs. 11-14)."""
        vo, zo, th, w, Rb, l2, d, rho, r = self.geometry(z)
        cw, n = self.weights, self.dec.n
        jt = cw.transport * np.mean((rho - self.rho0) ** 2) + cw.load_share * np.sum(
            (w - 1 / n) ** 2)
        jp = cw.passable * ((2 * Rb + 2 * self.ds) / self.w_ref) ** 2
        jc = 0.0
        if self.crossing:
            iu, ju = self.pairs
            g2 = np.sum((r[iu] - r[ju]) ** 2, axis=1)
            jc = (cw.crossing_height * ((zo - self.z_lo) / self.zr) ** 2
                  + cw.crossing_gap * np.mean(self.sep ** 2 / np.maximum(g2, _tol.SQUARE_FLOOR)))
        return float(jt + jp + jc)

    def equalities(self, z: np.ndarray) -> np.ndarray:
        """:math:`\\sum w_i = 1`, :math:`\\sum w_i v_i = v_o`, :math:`\\sum w_i r_i = 0`."""
        vo, zo, th, w, Rb, l2, d, rho, r = self.geometry(z)
        return np.concatenate([[w.sum() - 1.0], w @ self.V - vo, w @ r])

    def inequalities(self, z: np.ndarray) -> np.ndarray:
        """(15b)-(15c) as ``g(z) >= 0``."""
        vo, zo, th, w, Rb, l2, d, rho, r = self.geometry(z)
        iu, ju = self.pairs
        g2 = np.sum((r[iu] - r[ju]) ** 2, axis=1)
        return np.concatenate([w - MIN_SHARE, l2 - d * d - _tol.STRICT_SLACK, self.vd2 - g2,
                               g2 - self.sep ** 2,
                               Rb ** 2 - (r[:, 1] ** 2 if self.narrow else rho ** 2),
                               [zo - self.z_lo, self.z_hi - zo, self.r_max - Rb]])

    def admissible(self, z: np.ndarray) -> bool:
        tol = _tol.FORMATION_FEAS_TOL
        return bool(np.abs(self.equalities(z)).max() <= tol
                    and self.inequalities(z).min() >= -tol)

    def from_ik(self, ik, s: float) -> np.ndarray:
        """Decision vector of an IK solution (lengths divided by the sheet size ``s``)."""
        return self.dec.pack(ik.contact / s, ik.object[2] / s, ik.angles, ik.weights,
                             ik.reach.max() / s * 1.01)


def _curvature_constraint(team: Team, prob: _Problem, s: float):
    """Positive reduced-Hessian curvature (a stable rest state; used for N <= 4)."""
    def curvature(z: np.ndarray) -> np.ndarray:
        vo, zo, th, w, _ = prob.dec.split(z)
        try:
            c = ik_constraints(team.carrier, [0.0, 0.0, zo * s], th, w, contact=vo * s)
        except TautError:
            return np.array([-1.0])
        k = float(np.min(c.curvature))
        return np.array([-1.0 if np.isnan(k) else min(k, 1.0) - _tol.MIN_CURVATURE])
    return curvature


def _nominal_ik(team: Team, heights: np.ndarray):
    """First IK solution at the sheet centroid among object ``heights`` (m)."""
    for zo in heights:
        try:
            ik = inverse_kinematics(team.carrier, [0.0, 0.0, zo])
        except TautError:              # e.g. the object at or above the hold height
            continue
        if ik.success:                 # unreachable / budget exhausted: try the next height
            return ik
    return None


def _problem(team: Team, kind: str, height: float, diameter: float, width: float | None,
             max_reach: float | None, weights: CostWeights | None, sheet_margin: float):
    """The normalised problem and its nominal IK start, or None when infeasible."""
    sheet, zr = team.sheet, team.hold_height
    s, N = sheet.size, sheet.n
    crossing = kind == "crossing" and height > 0
    z_lo = max(height + team.height_safety if crossing else 0.0, team.height_safety,
               1e-3 * zr) / s
    z_hi = (1 - MIN_DEPTH_FRACTION) * zr / s
    if z_lo > z_hi:
        return None, None
    V = sheet.vertices / s
    iu, ju = np.triu_indices(N, 1)
    vd = np.linalg.norm(V[iu] - V[ju], axis=1) - sheet_margin / s
    sep = max(2 * team.robot_radius, (diameter + 2 * team.clearance) if crossing else 0.0)
    # Cheap necessary condition first: every pair gap is at most its sheet distance
    # (15c) and at least ``sep`` (15b), so a sheet pair closer than ``sep`` is infeasible.
    if np.any(vd <= 0) or np.any(vd < sep / s):
        return None, None
    start = _nominal_ik(team, np.linspace(z_lo, z_hi, 7) * s)
    if start is None:
        return None, None
    prob = _Problem(V=V, zr=zr / s, z_lo=z_lo, z_hi=z_hi, sep=sep / s,
                    ds=team.clearance / s, w_ref=(width if width is not None else 4 * s) / s,
                    r_max=1e6 if max_reach is None else (max_reach - team.clearance) / s,
                    vd2=vd ** 2 * (1 - _tol.STRICT_SLACK), rho0=start.reach / s, crossing=crossing,
                    weights=weights or (COMPACT if kind in ("compact", "narrow")
                                        else CostWeights()),
                    dec=_Decision(N), narrow=kind == "narrow")
    return prob, start
