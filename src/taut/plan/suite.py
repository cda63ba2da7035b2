"""Seeded generator of cluttered corridors for 3-8 robot teams (benchmark suite).

Each scenario: a straight or L-turned corridor, a regular ``N``-gon sheet (side about
0.7 m) held at a height below its circumradius, 1-4 obstacles (cylinders or convex prisms)
of random size and height (some too tall to cross), start and goal at the two ends. The
corridor width is drawn between the compact formation's and the crossing formation's
widths, so bypassing is often blocked while crossing often is not: the regime the planning
paper targets. Obstacles are at least a crossing formation's diameter apart (the planner
crosses one obstacle at a time). Same seed, same suite.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Point, Polygon

from .._validate import as_count
from ..sheet import Sheet, SheetTeam
from .formations.optimal import _optimal_formation
from .world import Obstacle, Scenario, Team, World

#: Crossable obstacles are at most this fraction of the holding height tall.
CROSS_FRACTION = 0.35

__all__ = ["generate_scenario", "generate_suite"]


def _team(rng: np.random.Generator, n: int) -> Team:
    side = rng.uniform(0.6, 0.8)
    circ = side / (2 * np.sin(np.pi / n))
    sheet = Sheet.regular(n, circ, phase=rng.uniform(0, 2 * np.pi / n))
    return Team(SheetTeam(sheet, rng.uniform(0.55, 0.75) * circ), robot_radius=0.1,
                height_safety=0.04, lateral_safety=0.04, speed=0.2, rotation_speed=0.5)


def _reaches(team: Team) -> tuple[float, float]:
    """Reach (m) of the compact formation and of a formation crossing obstacles up to
    ``CROSS_FRACTION`` of the holding height (falls back to the compact one)."""
    compact = _optimal_formation(team, "compact")
    if compact is None:
        raise RuntimeError("suite team cannot hold the object")  # pragma: no cover
    cross = _optimal_formation(team, "crossing", height=CROSS_FRACTION * team.hold_height,
                               diameter=0.2)
    return compact.reach, (cross or compact).reach


def _corridor(rng: np.random.Generator, width: float, turned: bool
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[np.ndarray]]:
    """Free-space polygon, start, goal and the centre-line segments of the corridor."""
    if not turned:
        length = rng.uniform(6.0, 10.0)
        poly = np.array([[0, 0], [length, 0], [length, width], [0, width]])
        line = [np.array([0, width / 2]), np.array([length, width / 2])]
        return poly, line[0], line[1], line
    a, b = rng.uniform(4.0, 6.0), rng.uniform(3.5, 5.0)
    poly = np.array([[0, 0], [a, 0], [a, b], [a - width, b], [a - width, width], [0, width]])
    line = [np.array([0, width / 2]), np.array([a - width / 2, width / 2]),
            np.array([a - width / 2, b])]
    return poly, line[0], line[-1], line


def generate_scenario(seed: int, n_robots: int | None = None) -> Scenario:
    """One seeded cluttered-corridor scenario.

    Parameters
    ----------
    seed : int
    n_robots : int, optional
        3..8 (default: drawn from the seed).

    Returns
    -------
    Scenario
    """
    seed = as_count(seed, "seed", minimum=0)
    if n_robots is not None:
        n_robots = as_count(n_robots, "n_robots", minimum=3, maximum=8)
    return _generate_scenario(seed, n_robots)


def _generate_scenario(seed: int, n_robots: int | None) -> Scenario:
    """:func:`generate_scenario` on validated inputs."""
    rng = np.random.default_rng(seed)
    n = n_robots if n_robots is not None else int(rng.integers(3, 9))
    team = _team(rng, n)
    low, high = _reaches(team)
    width = rng.uniform(2.05 * low + 0.1, 2.05 * max(high, low) + 0.8)
    poly, start_c, goal_c, line = _corridor(rng, width, turned=bool(rng.random() < 0.3))
    free = Polygon(poly)
    along = [np.linalg.norm(q - p) for p, q in zip(line[:-1], line[1:])]
    total = sum(along)
    keep_out = high + 0.1
    start = start_c + (line[1] - line[0]) / along[0] * keep_out
    goal = goal_c - (line[-1] - line[-2]) / along[-1] * keep_out
    obstacles: list[Obstacle] = []
    geoms: list[Polygon] = []
    want = int(rng.integers(1, 5))
    for _ in range(200):
        if len(obstacles) >= want:
            break
        s = rng.uniform(2 * keep_out + 0.2, total - 2 * keep_out - 0.2)
        k = 0
        while s > along[k]:
            s -= along[k]
            k += 1
        p = line[k] + (line[k + 1] - line[k]) / along[k] * s
        normal = np.array([-(line[k + 1] - line[k])[1], (line[k + 1] - line[k])[0]]) / along[k]
        p = p + normal * rng.uniform(-0.3, 0.3) * width
        r = rng.uniform(0.04, 0.1)
        tall = rng.random() < 0.2
        h = rng.uniform(0.6, 1.2) * team.hold_height if tall else \
            rng.uniform(0.05, CROSS_FRACTION) * team.hold_height
        oid = f"o{len(obstacles) + 1}"
        if rng.random() < 0.7:
            ob = Obstacle(oid, h, center=p, radius=r)
        else:
            t = np.sort(rng.uniform(0, 2 * np.pi, int(rng.integers(3, 6))))
            pts = p + r * np.column_stack([np.cos(t), np.sin(t)])
            try:
                ob = Obstacle(oid, h, polygon=pts)
            except Exception:  # noqa: BLE001 - degenerate draw, try again
                continue
        g = ob.geometry
        if not free.buffer(-0.02).contains(g) or any(g.distance(q) < 2 * high for q in geoms):
            continue
        if min(g.distance(Point(start)), g.distance(Point(goal))) < keep_out + 0.05:
            continue
        obstacles.append(ob)
        geoms.append(g)
    world = World(poly, tuple(obstacles))
    return Scenario(world, team, start, goal, name=f"suite-{seed}-N{n}")


def generate_suite(count: int = 50, seed: int = 2024) -> list[Scenario]:
    """``count`` scenarios, robot counts cycling through 3..8, seeds ``seed + i``."""
    count = as_count(count, "count", minimum=0, maximum=100_000)
    seed = as_count(seed, "seed", minimum=0, maximum=2**63 - 1 - count)
    return [_generate_scenario(seed + i, 3 + i % 6) for i in range(count)]
