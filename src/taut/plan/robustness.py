"""Seeded Monte Carlo of a plan under robot position error (issue 14, item 4).

Each trial displaces every robot at every sample independently (uniformly within a disc of
radius ``sigma``, or normally with standard deviation ``sigma`` per axis) and records
whether some robot pair is beyond its sheet distance (the sheet tears) and, at the
``checked`` samples with the least height margin, whether the lowest rest state of the
perturbed formation (forward kinematics) still clears the obstacles beneath and the
ground by the height safety.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely

from ..errors import InvalidInputError, TautError
from ..sheet import forward_kinematics
from .world import Scenario

if TYPE_CHECKING:
    from .result import PlanResult, Robustness

__all__: list[str] = []


def _beneath(scenario: Scenario, robots: np.ndarray) -> np.ndarray:
    """Tallest obstacle under the robots' hull per sample, m (0 when none)."""
    hulls = shapely.convex_hull(shapely.multipoints(robots))
    out = np.zeros(len(robots))
    for o in scenario.world.obstacles:
        out = np.where(shapely.intersects(hulls, o.geometry), np.maximum(out, o.height), out)
    return out


def _noise(rng: np.random.Generator, shape: tuple[int, ...], sigma: float, kind: str
           ) -> np.ndarray:
    if kind == "gaussian":
        return rng.normal(0.0, sigma, (*shape, 2))
    r = sigma * np.sqrt(rng.uniform(0, 1, shape))
    a = rng.uniform(0, 2 * np.pi, shape)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=-1)


def monte_carlo(scenario: Scenario, result: "PlanResult", sigma: float, trials: int, *,
                noise: str = "disc", seed: int = 0, checked: int = 8) -> "Robustness":
    """Tear and drop probabilities of ``result`` under robot position error ``sigma`` (m).

    Returns
    -------
    Robustness
    """
    from .result import Robustness
    if not (np.isfinite(sigma) and sigma >= 0):
        raise InvalidInputError("sigma", "must be a finite length >= 0")
    if int(trials) < 1:
        raise InvalidInputError("trials", "must be at least 1")
    if noise not in ("disc", "gaussian"):
        raise InvalidInputError("noise", "must be 'disc' or 'gaussian'")
    team = scenario.team
    rng = np.random.default_rng(seed)
    R = np.asarray(result.robots)
    V = team.sheet.vertices
    iu, ju = np.triu_indices(V.shape[0], 1)
    limit = np.linalg.norm(V[iu] - V[ju], axis=1)
    floor = _beneath(scenario, R)
    margin = result.object[:, 2] - floor
    worst = np.argsort(margin)[:checked]
    tears = drops = 0
    worst_ext = -np.inf
    for _ in range(int(trials)):
        P = R + _noise(rng, R.shape[:2], sigma, noise)
        ext = np.linalg.norm(P[:, iu] - P[:, ju], axis=2) - limit
        worst_ext = max(worst_ext, float(ext.max()))
        if ext.max() > 0:
            tears += 1
            continue
        for t in worst:
            try:
                fk = forward_kinematics(team.sheet, P[t], team.hold_height)
            except TautError:
                drops += 1
                break
            low = fk.lowest
            if low is None or low.height - floor[t] < team.height_safety:
                drops += 1
                break
    return Robustness(float(sigma), noise, int(trials), tears / trials, drops / trials,
                      worst_ext)
