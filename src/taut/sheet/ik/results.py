"""Result types of inverse kinematics (:func:`taut.sheet.inverse_kinematics`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._outcome import check_status
from ._certificate import IKCertificate
from .._tol import IK_FEASIBLE_RTOL, TINY
from ..model import GEOMETRY_RTOL
from ..._repr import CompactRepr

__all__ = ["IKResult", "IKConstraints"]


@dataclass(frozen=True, eq=False, repr=False)
class IKResult(CompactRepr):
    """Outcome of inverse kinematics: a formation that holds the object stably at the
    target with every cable taut, or why there is none.

    Attributes
    ----------
    formation : ndarray, shape (N, 2)
        Robot positions :math:`\\mathbf{r}_i` (world frame, length unit of the sheet); NaN
        when ``success`` is false.
    object : ndarray, shape (3,)
        The target :math:`\\mathbf{p}_o = (x_o, y_o, z_o)`.
    contact : ndarray, shape (2,)
        Contact point :math:`\\mathbf{v}_o` in the sheet frame.
    angles : ndarray, shape (N,)
        :math:`\\theta_i` of eq. (10), radians, in (-pi, pi] (NaN on failure).
    weights : ndarray, shape (N,)
        Vertical load shares :math:`w_i > 0` (sum 1; NaN on failure).
    tensions : ndarray, shape (N,), or None
        :math:`F_i = w_i m g l_i / d` in N when a mass was given (and success).
    cable_lengths : ndarray, shape (N,)
        :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|`.
    reach : ndarray, shape (N,)
        Horizontal robot-object distances :math:`\\rho_i = \\sqrt{l_i^2 - d^2}` (NaN when
        the object is deeper than a cable is long).
    curvature : float
        Smallest eigenvalue of the reduced Hessian (``inf`` when the cables fix the state).
    spacing : float
        Smallest :math:`(|\\mathbf{v}_i - \\mathbf{v}_j| - |\\mathbf{r}_i - \\mathbf{r}_j|)` over
        robot pairs (>= 0: a feasible formation; 0 for a pair at exactly its limit).
    construction : {"closure", "optimised", "search", "none"}
        The stage that found the formation (module docstring, steps 2, 3, 4).
    success : bool
        A verified formation was found.
    status : {"ok", "unreachable", "budget_exhausted"}
        ``unreachable`` only with a ``certificate``.
    message : str
        One line: what was found, or why not.
    certificate : IKCertificate or None
        The proof that the target is unreachable (status ``unreachable``).
    attempts : int
        Optimiser runs used (joint optimisation and multi-start search).
    unmet : tuple of str
        Conditions of the answer IK could not meet, from ``"sheet_margin"`` (a robot pair
        closer than the margin to its sheet distance) and ``"robustness"`` (the object not
        held under the position error); empty when both are met or there is no formation.
    """

    formation: np.ndarray
    object: np.ndarray
    contact: np.ndarray
    angles: np.ndarray
    weights: np.ndarray
    tensions: np.ndarray | None
    cable_lengths: np.ndarray
    reach: np.ndarray
    curvature: float
    spacing: float
    construction: str
    success: bool = True
    status: str = "ok"
    message: str = ""
    certificate: IKCertificate | None = field(default=None, repr=False)
    attempts: int = 0
    unmet: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        check_status(self.status)

    @property
    def min_weight(self) -> float:
        """Smallest cable weight."""
        return float(self.weights.min())


@dataclass(frozen=True, eq=False, repr=False)
class IKConstraints(CompactRepr):
    """Conditions of an all-taut stable rest state for given angles (and weights).

    Every field is zero/non-negative at a valid IK solution; optimisers over the angles
    :math:`\\theta_i` of eq. (10) can use them as constraints.

    Attributes
    ----------
    formation : ndarray, shape (..., N, 2)
        Robots from eq. (10).
    weights : ndarray, shape (..., N)
        The weights used (given, or the least-squares weights satisfying the contact and
        balance equations best).
    balance : ndarray, shape (..., 2)
        Horizontal balance :math:`\\sum w_i(\\mathbf{r}_i - \\mathbf{r}_o)` (must be 0), in
        length units.
    contact_residual : ndarray, shape (..., 3)
        :math:`(\\sum w_i - 1, \\sum w_i \\mathbf{v}_i - \\mathbf{v}_o)` (must be 0).
    spacing : ndarray, shape (..., N(N-1)/2)
        :math:`|\\mathbf{v}_i - \\mathbf{v}_j| - |\\mathbf{r}_i - \\mathbf{r}_j|` for pairs
        ``i < j`` in ``numpy.triu_indices`` order (must be >= 0).
    min_weight : ndarray, shape (...)
        (must be > 0).
    curvature : ndarray, shape (...)
        Smallest reduced-Hessian eigenvalue (must be > 0; ``inf`` when fixed).
    """

    formation: np.ndarray
    weights: np.ndarray
    balance: np.ndarray
    contact_residual: np.ndarray
    spacing: np.ndarray
    min_weight: np.ndarray
    curvature: np.ndarray

    @property
    def feasible(self) -> np.ndarray:
        """Bool (...): every condition holds (tolerances relative to the balance scale)."""
        scale = np.max(np.abs(self.formation - self.formation.mean(axis=-2, keepdims=True)),
                       axis=(-2, -1))
        tol = IK_FEASIBLE_RTOL
        return ((np.linalg.norm(self.balance, axis=-1) <= tol * np.maximum(scale, TINY))
                & (np.abs(self.contact_residual).max(axis=-1) <= tol * np.maximum(scale, 1))
                & (self.spacing.min(axis=-1) >= -GEOMETRY_RTOL * np.maximum(scale, TINY))
                & (self.min_weight > 0) & (self.curvature > 0))
