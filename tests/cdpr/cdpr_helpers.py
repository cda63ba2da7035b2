"""Shared helpers of the cable-robot tests (random poses, hand-checkable robots)."""

import numpy as np

from taut.cdpr import Base, Cable, CableRobot, Payload, Platform


def random_poses(robot, n, seed, angle=0.15, margin=0.05):
    """Uniform random poses inside the frame box (shrunk by ``margin`` of its size) with
    roll, pitch, yaw uniform in +-angle rad."""
    g = np.random.default_rng(seed)
    lo, hi = robot.bounds
    span = hi - lo
    pos = g.uniform(lo + margin * span, hi - margin * span, (n, 3))
    return np.column_stack([pos, g.uniform(-angle, angle, (n, 3))])


A, H, MASS = 1.0, 3.0, 4.0          # half-width of the square frame, its height, point mass


def point_mass_robot(t_min=2.0, t_max=60.0):
    """Four cables from the top corners (+-A, +-A, H) of a square frame to a point mass:
    the hand-checkable symmetric robot."""
    exits = {f"A{i}": (sx * A, sy * A, H)
             for i, (sx, sy) in enumerate([(1, 1), (-1, 1), (-1, -1), (1, -1)])}
    return CableRobot(
        bases=(Base("frame", exits),),
        platform=Platform({"P": (0.0, 0.0, 0.0)}, mass=MASS),
        cables=tuple(Cable(f"C{i}", "frame", f"A{i}", "P", t_min, t_max) for i in range(4)),
        payload=Payload(0.0),
        name="point mass")


def twelve_cable_robot(t_min=5.0, t_max=400.0, mass=20.0):
    """Twelve cables (six redundant) on a fixed 4 m x 4 m x 3 m frame: exits at the 4 top
    corners, the 4 top edge midpoints and the 4 bottom corners; each to its own anchor on a
    1 m x 1 m x 0.5 m platform. Beyond the exact enumeration (at most 2 redundant)."""
    top = [(sx * 2.0, sy * 2.0, 3.0) for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]]
    mid = [(2.0, 0.0, 3.0), (0.0, 2.0, 3.0), (-2.0, 0.0, 3.0), (0.0, -2.0, 3.0)]
    low = [(sx * 2.0, sy * 2.0, 0.0) for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]]
    exits = {f"E{i}": p for i, p in enumerate(top + mid + low)}
    up = [(sx * 0.5, sy * 0.5, 0.25) for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]]
    side = [(0.5, 0.0, 0.25), (0.0, 0.5, 0.25), (-0.5, 0.0, 0.25), (0.0, -0.5, 0.25)]
    down = [(sx * 0.5, sy * 0.5, -0.25) for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]]
    c, s = np.cos(0.35), np.sin(0.35)         # upper anchors turned +20 deg, lower -20 deg:
    turn = [(c * x - k * s * y, k * s * x + c * y, z)   # cables not radial: yaw is held
            for (x, y, z), k in zip(up + side + down, [1] * 8 + [-1] * 4)]
    anchors = {f"P{i}": p for i, p in enumerate(turn)}
    return CableRobot(
        bases=(Base("frame", exits),),
        platform=Platform(anchors, mass=mass, inertia=(0.5, 0.5, 0.5)),
        cables=tuple(Cable(f"C{i}", "frame", f"E{i}", f"P{i}", t_min, t_max)
                     for i in range(12)),
        payload=Payload(0.0),
        name="twelve cables")


def bisect_largest(ok, hi, iters=14):
    """Largest value in [0, hi] for which the monotone predicate ``ok`` holds, by
    ``iters`` bisection steps (the lower end of the last bracket)."""
    lo = 0.0
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo
