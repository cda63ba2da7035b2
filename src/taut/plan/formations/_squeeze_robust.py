"""Does a formation's rest state survive the robots' position error? (Our requirement on
squeezed formations, :mod:`taut.plan.formations._squeezed`.)

A formation with slack cables can be stable yet sit in so flat a valley of the potential
that a few millimetres of robot error slide the object tens of centimetres, out of its taut
robots' polygon, and off the sheet. The check perturbs every robot by seeded errors
uniform in a disc of radius ``POSITION_ACCURACY`` (the accuracy ``sheet_margin`` is sized
for) and requires, for each perturbation, a stable state (forward kinematics) within
``SQUEEZE_MAX_SHIFT`` of the unperturbed object, at least ``z_min`` high, with the object
inside the polygon of its taut robots (the taut cables may change: a cable that goes slack
or taut moves the object continuously; what must not happen is a slide far away, or off
the sheet). The bound is about the 90th percentile of
what the all-taut formations of the seed-2024 suite shift under the same errors (median
1.9 cm, 90th percentile 4.1 cm, at most 15 cm over 12 draws each); a squeezed formation
that needs it is not admitted.
"""

from __future__ import annotations

import numpy as np

from ..._geometry import convex_hull_2d
from ...errors import TautError
from ...sheet import Equilibrium, FKSolver, object_covariance
from .. import _options, _tol
from ..checks.robustness import _noise

__all__ = ["tolerates", "linear_rejects", "convex_hull", "hull_inset"]

#: Perturbations drawn per check: a formation that loses its state under one error in
#: twenty passes 12 draws half the time, 100 draws 0.6 % of it.
LIBRARY_DRAWS = 100
#: Seed of the perturbations (the check is deterministic).
SEED = 20241


def convex_hull(P: np.ndarray) -> np.ndarray | None:
    """Vertices of the convex hull of ``P`` (k, 2), counter-clockwise
    (:func:`taut._geometry.convex_hull_2d`); None without area (fewer than three points
    off one line)."""
    hull = convex_hull_2d(P)
    return hull if len(hull) >= 3 else None


def hull_inset(P: np.ndarray, q: np.ndarray) -> float:
    """Distance of ``q`` inside the convex hull of ``P`` (< 0 outside; -inf for no area)."""
    hull = convex_hull(P)
    if hull is None:
        return -np.inf
    E = np.roll(hull, -1, axis=0) - hull
    Q = q - hull
    return float(np.min((E[:, 0] * Q[:, 1] - E[:, 1] * Q[:, 0]) / np.linalg.norm(E, axis=1)))


def linear_rejects(state: Equilibrium, z_min: float, max_shift: float, sigmas: float,
                   accuracy: float = _tol.POSITION_ACCURACY) -> bool:
    """The linearised screen (:class:`~taut.plan._options.LinearScreen`): does the
    first-order prediction already fail :func:`tolerates`? Robot errors uniform in a disc
    of radius ``accuracy`` (m) have variance ``accuracy**2 / 4`` per axis; through the
    state's ``jacobian`` (:func:`taut.sheet.object_covariance`) the object height has the
    predicted standard deviation ``s_z`` and the object shift the root mean square
    ``s = sqrt(trace)``. Rejects when ``height - z_min < sigmas * s_z`` or
    ``max_shift < sigmas * s`` (with ``LIBRARY_DRAWS`` draws the sampling sees a
    deviation beyond one standard deviation all but surely). A state whose jacobian is not
    finite (a singular taut set) is not screened."""
    cov = object_covariance(state, accuracy ** 2 / 4.0)
    if not np.all(np.isfinite(cov)):
        return False
    s_z, s = np.sqrt(max(cov[2, 2], 0.0)), np.sqrt(max(np.trace(cov), 0.0))
    return bool(state.height - z_min < sigmas * s_z or max_shift < sigmas * s)


def tolerates(solver: FKSolver, robots: np.ndarray, state: Equilibrium, z_min: float,
              max_shift: float = _tol.SQUEEZE_MAX_SHIFT, draws: int = LIBRARY_DRAWS) -> bool:
    """Does the rest state ``state`` of ``robots`` (N, 2, m) survive the perturbations
    (module docstring)? ``z_min``: least object height, m; ``max_shift``: farthest the
    object may move, m (the library's all-taut formations are held to inf: only a lost
    state or an object on the ground rejects them); ``draws``: perturbations tried."""
    screen = _options.LINEAR_SCREEN
    if screen.enabled and linear_rejects(state, z_min, max_shift, screen.sigmas):
        return False
    rng = np.random.default_rng(SEED)
    n = robots.shape[0]
    for _ in range(draws):
        P = robots + _noise(rng, (n,), _tol.POSITION_ACCURACY, "disc")
        try:
            stable = solver.solve(np.ascontiguousarray(P), check=False).stable
        except TautError:
            return False
        if not stable:
            return False
        e = min(stable, key=lambda e: float(np.linalg.norm(e.object - state.object)))
        if (np.linalg.norm(e.object - state.object) > max_shift
                or e.height < z_min or hull_inset(P[list(e.taut)], e.object[:2]) <= 0):
            return False
    return True
