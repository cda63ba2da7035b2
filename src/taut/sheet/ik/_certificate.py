"""Proofs that no stable all-taut formation holds the object at a target
(docs/sheet_kinematics.md §6, planning paper eq. 10).

In the normalised frame of a target (object over the origin, contact at the origin, lengths
divided by the sheet size), robot ``i`` stands at :math:`\\mathbf{r}_i = \\rho_i
\\mathbf{u}(\\theta_i)`. A formation exists iff some weights :math:`w` in the polytope
:math:`W = \\{w \\ge 0, \\sum w_i = 1, \\sum w_i \\mathbf{v}_i = 0\\}` and angles satisfy

* closure :math:`\\sum_i a_i \\mathbf{u}(\\theta_i) = 0` with :math:`a_i = w_i \\rho_i`;
* the pairwise limits :math:`|\\mathbf{r}_i - \\mathbf{r}_j| \\le D_{ij} = |\\mathbf{v}_i -
  \\mathbf{v}_j|`, i.e. :math:`\\cos(\\theta_i - \\theta_j) \\ge c_{ij} = (\\rho_i^2 +
  \\rho_j^2 - D_{ij}^2) / (2 \\rho_i \\rho_j)`.

Five certificates, each checkable by :func:`verify_certificate` from the target alone:

``depth``
    The object is not strictly between the hands and a cable's full length below them:
    :math:`0 < d < \\min_i l_i` fails (then :math:`\\rho_i` is not real).
``radial_spacing``
    Some :math:`c_{ij} > 1`: two robots at horizontal distances :math:`\\rho_i, \\rho_j`
    are at least :math:`|\\rho_i - \\rho_j| > D_{ij}` apart, whatever the angles.
``triangle``
    N = 3: :math:`W` is the single point of barycentric weights, so the closing polygon is
    a triangle with fixed sides, unique up to congruence; either the sides violate the
    triangle inequality or the triangle's angle between two cables breaks their limit.
``closure_lp``
    A linear relaxation. Projecting the closure on :math:`\\mathbf{u}_i` gives :math:`a_i
    = -\\sum_{j \\ne i} a_j \\cos(\\theta_j - \\theta_i) \\le \\sum_{j \\ne i} m_{ij} a_j`
    with :math:`m_{ij} = \\min(1, -c_{ij})` (the limits bound the cosine from below), so
    every formation's weights lie in :math:`\\{w \\in W : M w \\le 0\\}`, :math:`M_{ii} =
    \\rho_i`, :math:`M_{ij} = -m_{ij}\\rho_j`. It is empty (Farkas) iff there are
    :math:`y \\ge 0`, :math:`\\sum y = 1`, :math:`\\lambda \\in R^2` with :math:`g_k =
    (M^T y)_k + \\lambda \\cdot \\mathbf{v}_k > 0` for every ``k``: then every :math:`w \\in
    W` has :math:`y^T M w = \\sum_k w_k g_k > 0`, so some cable cannot be balanced. The
    certificate stores ``y`` and ``lam``; the cosine bounds are loosened by
    RELAX_COS_SLACK so rounding only enlarges the relaxation.
``closure_branch``
    A tighter relaxation, branched: the closure seen from every cable's own frame with the
    other cables' angles confined to arcs, the angle space split into boxes until each box
    is refuted by one pair limit or by that relaxation (:mod:`taut.sheet.ik._branch`); the
    certificate stores the tree of splits and each leaf's multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.optimize import linprog

from ._branch import BranchProof, branch_proof, pair_cosine_limits, verify_branch_proof
from .._tol import (CERTIFICATE_MIN_MARGIN, DEPTH_RTOL, MULTIPLIER_SUM_TOL, RELAX_COS_SLACK,
    SPACING_MARGIN)
from ..._repr import CompactRepr

__all__ = ["IKCertificate", "CertificateKind", "depth_certificate", "radial_certificate",
           "triangle_certificate", "closure_lp_certificate", "verify_certificate",
           "closure_branch_certificate"]

CertificateKind = Literal["depth", "radial_spacing", "triangle", "closure_lp",
                          "closure_branch"]


@dataclass(frozen=True, eq=False, repr=False)
class IKCertificate(CompactRepr):
    """Why no stable all-taut formation exists for a target (module docstring).

    Attributes
    ----------
    kind : {"depth", "radial_spacing", "triangle", "closure_lp", "closure_branch"}
    message : str
        One line in words.
    pair : tuple of int, or None
        The robot pair (0-based) of a ``radial_spacing`` or ``triangle`` proof.
    multipliers : ndarray, shape (N,), or None
        ``y`` of a ``closure_lp`` proof (>= 0, sum 1).
    direction : ndarray, shape (2,), or None
        ``lam`` of a ``closure_lp`` proof (normalised units).
    margin : float
        How strictly the proof holds (normalised units; >= 0, 0 only for an object at
        exactly the holding height).
    proof : BranchProof, or None
        The refutation tree of a ``closure_branch`` proof (:mod:`taut.sheet.ik._branch`).
    """

    kind: CertificateKind
    message: str
    pair: tuple[int, int] | None = None
    multipliers: np.ndarray | None = field(default=None, repr=False)
    direction: np.ndarray | None = field(default=None, repr=False)
    margin: float = 0.0
    proof: BranchProof | None = field(default=None, repr=False)


def depth_certificate(depth: float, lengths: np.ndarray, hold_height: float
                      ) -> IKCertificate | None:
    """Proof when :math:`0 < d < \\min l_i` fails (``depth`` d, cable lengths (N,))."""
    if not depth > 0.0:
        return IKCertificate("depth", f"object height {hold_height - depth:.6g} is not "
                             f"below the holding height {hold_height:.6g}", margin=-depth)
    short = lengths <= depth * (1 + DEPTH_RTOL)
    if not np.any(short):
        return None
    i = int(np.argmin(lengths))
    return IKCertificate("depth", f"object too deep: depth {depth:.6g} below the robots but "
                         f"the cable to vertex {i + 1} is only {lengths[i]:.6g} long (raise "
                         "the object or move the contact point away from that vertex)",
                         margin=float(depth - lengths[i]))


def radial_certificate(V: np.ndarray, rho: np.ndarray, scale: float) -> IKCertificate | None:
    """The pair proof :math:`|\\rho_i - \\rho_j| > D_{ij}` (normalised V, rho)."""
    D = np.linalg.norm(V[:, None, :] - V[None, :, :], axis=2)
    excess = np.abs(rho[:, None] - rho[None, :]) - D
    k = int(np.argmax(excess))
    i, j = divmod(k, len(rho))
    if not excess.flat[k] > SPACING_MARGIN:
        return None
    i, j = min(i, j), max(i, j)
    return IKCertificate(
        "radial_spacing", f"no all-taut formation exists for this target and contact: "
        f"robots {i + 1} and {j + 1} must stand {rho[i] * scale:.6g} and "
        f"{rho[j] * scale:.6g} from the object horizontally, at least "
        f"{abs(rho[i] - rho[j]) * scale:.6g} apart, but the sheet holds them at most "
        f"{D[i, j] * scale:.6g} apart", pair=(i, j), margin=float(excess.flat[k]))


def triangle_certificate(V: np.ndarray, rho: np.ndarray, w: np.ndarray
                         ) -> IKCertificate | None:
    """N = 3 exact test: sides ``a = w rho`` of the (unique) closing triangle."""
    if len(rho) != 3:
        return None
    a = w * rho
    big = int(np.argmax(a))
    if a[big] >= a.sum() - a[big] - SPACING_MARGIN * a.sum():
        return IKCertificate("triangle", f"cable {big + 1} would pull sideways harder than "
                             "the other two together (horizontal forces cannot balance)",
                             pair=None, margin=float(2 * a[big] - a.sum()))
    c = pair_cosine_limits(V, rho)
    for i, j in ((0, 1), (0, 2), (1, 2)):
        k = 3 - i - j
        cos_ij = (a[k] ** 2 - a[i] ** 2 - a[j] ** 2) / (2 * a[i] * a[j])
        gap = c[i, j] - cos_ij                 # > 0: the pair stands too far apart
        if gap > RELAX_COS_SLACK + SPACING_MARGIN:
            return IKCertificate(
                "triangle", f"the balanced robots would stand farther apart than the sheet "
                f"allows: with three cables the load shares fix the closing triangle, which "
                f"puts robots {i + 1} and {j + 1} beyond their sheet distance",
                pair=(i, j), margin=float(gap))
    return None


def _relaxation_matrix(V: np.ndarray, rho: np.ndarray) -> np.ndarray:
    m = np.minimum(1.0, -pair_cosine_limits(V, rho) + RELAX_COS_SLACK)
    M = -m * rho[None, :]
    np.fill_diagonal(M, rho)
    return M


def _separation(V: np.ndarray, rho: np.ndarray, y: np.ndarray, lam: np.ndarray
                ) -> np.ndarray:
    return _relaxation_matrix(V, rho).T @ y + V @ lam


def closure_lp_certificate(V: np.ndarray, rho: np.ndarray) -> IKCertificate | None:
    """Search the Farkas certificate of the linear relaxation (module docstring): maximise
    ``t`` subject to ``g_k >= t``, ``y >= 0``, ``sum y = 1``; a proof when ``t`` is
    clearly positive."""
    N = len(rho)
    M = _relaxation_matrix(V, rho)
    # variables (y (N), lam (2), t); maximise t  <=>  minimise -t
    cost = np.zeros(N + 3)
    cost[-1] = -1.0
    A_ub = np.hstack([-M.T, -V, np.ones((N, 1))])          # t - g_k <= 0
    A_eq = np.zeros((1, N + 3))
    A_eq[0, :N] = 1.0
    bounds = [(0, None)] * N + [(None, None)] * 2 + [(None, 1.0)]
    lp = linprog(cost, A_ub=A_ub, b_ub=np.zeros(N), A_eq=A_eq, b_eq=[1.0], bounds=bounds,
                 method="highs")
    if not lp.success:
        return None
    y, lam = np.maximum(lp.x[:N], 0.0), lp.x[N:N + 2]
    y = y / y.sum()
    margin = float(_separation(V, rho, y, lam).min())
    if not margin > CERTIFICATE_MIN_MARGIN * max(1.0, float(rho.max())):
        return None
    return IKCertificate(
        "closure_lp", "no all-taut formation exists for this target and contact: the "
        "pairwise sheet limits bound how far the cables' horizontal pulls can oppose each "
        "other, and no load shares of this contact point balance them (LP relaxation of "
        "the polygon-closing condition is infeasible)", multipliers=y, direction=lam,
        margin=margin)


def closure_branch_certificate(V: np.ndarray, rho: np.ndarray, max_boxes: int
                               ) -> IKCertificate | None:
    """The branched frame relaxation (module docstring), within ``max_boxes`` boxes."""
    proof = branch_proof(V, rho, max_boxes=max_boxes)
    if proof is None:
        return None
    return IKCertificate(
        "closure_branch", "no all-taut formation exists for this target and contact: "
        f"every arrangement of the cable directions ({proof.boxes} boxes of angles "
        "examined) either puts a robot pair beyond its sheet distance or leaves the "
        "horizontal pulls unbalanced for every load share of this contact point",
        margin=CERTIFICATE_MIN_MARGIN, proof=proof)


def verify_certificate(cert: IKCertificate, V: np.ndarray, rho: np.ndarray,
                       depth: float, lengths: np.ndarray) -> bool:
    """Re-check a certificate from the target data alone (normalised V (N, 2) with the
    contact at the origin, reach ``rho`` (N,), depth and cable lengths in one unit)."""
    if cert.kind == "depth":
        return not (depth > 0.0 and lengths.min() > depth)
    if cert.kind == "radial_spacing":
        assert cert.pair is not None
        i, j = cert.pair
        return bool(abs(rho[i] - rho[j]) - np.linalg.norm(V[i] - V[j]) > 0.0)
    if cert.kind == "triangle":
        from ._weights import maxent_weights
        w = maxent_weights(V, np.zeros(2), 1.0)
        return len(rho) == 3 and triangle_certificate(V, rho, w) is not None
    if cert.kind == "closure_branch":
        return cert.proof is not None and verify_branch_proof(cert.proof, V, rho)
    y, lam = cert.multipliers, cert.direction
    if y is None or lam is None or np.any(y < 0) or abs(y.sum() - 1.0) > MULTIPLIER_SUM_TOL:
        return False
    return bool(_separation(V, rho, y, lam).min() > 0.0)
