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
