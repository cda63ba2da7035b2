"""Cable interference against brute-force sampling of the segments."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cdpr_helpers import random_poses
from taut.cdpr import cable_interference, cable_state, segment_distance


def _sampled_distance(p0, p1, q0, q1, n=401):
    s = np.linspace(0, 1, n)[:, None]
    a = p0 + s * (p1 - p0)
    b = q0 + s * (q1 - q0)
    d2 = ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)
    return np.sqrt(d2.min())


def _sampled_distance_rows(p0, p1, q0, q1, n=401):
    """The minimum of ``_sampled_distance``'s n x n grid in O(n): for each sample on the
    first segment the squared distance is convex in the second's parameter, so the grid
    minimum of that row is at one of the two samples around its unconstrained minimiser."""
    s = np.linspace(0, 1, n)
    a = p0 + s[:, None] * (p1 - p0)
    v = q1 - q0
    vv = v @ v
    t_star = np.clip(((a - q0) @ v) / vv if vv > 0 else np.zeros(n), 0.0, 1.0)
    k = np.clip(np.floor(t_star * (n - 1)).astype(int)[:, None] + [0, 1], 0, n - 1)
    b = q0 + s[k][..., None] * v                    # (n, 2, 3): the two candidate samples
    return np.sqrt(((a[:, None, :] - b) ** 2).sum(-1).min())


coord = st.floats(-2.0, 2.0, allow_nan=False)
point = st.tuples(coord, coord, coord).map(np.array)


@settings(max_examples=40, deadline=None)
@given(p0=point, p1=point, q0=point, q1=point, parallel=st.booleans())
def test_segment_distance_matches_sampling(p0, p1, q0, q1, parallel):
    if parallel:                                  # the degenerate case of the formula
        q1 = q0 + 0.7 * (p1 - p0)
    exact = segment_distance(p0, p1, q0, q1)
    sampled = _sampled_distance(p0, p1, q0, q1)
    step = (np.linalg.norm(p1 - p0) + np.linalg.norm(q1 - q0)) / 400
    assert exact <= sampled + 1e-12                # sampling never beats the minimum
    assert sampled <= exact + step + 1e-12        # and comes within its resolution
    assert segment_distance(q0, q1, p0, p1) == np.float64(exact) or np.isclose(
        segment_distance(q0, q1, p0, p1), exact, atol=1e-12)


def test_cable_distances_and_platform_collisions_match_sampling(fastkit):
    P = random_poses(fastkit, 6, seed=8, angle=0.4)
    res = cable_interference(fastkit, P)
    st_ = cable_state(fastkit, P)
    att = P[:, None, :3] + st_.r
    lo, hi = fastkit.attach_local.min(0), fastkit.attach_local.max(0)
    s = np.linspace(0, 1, 2001)[:, None]
    for b in range(len(P)):
        for i in range(fastkit.m):
            for j in range(i + 1, fastkit.m):
                if np.isfinite(res.distance[b, i, j]):
                    d = _sampled_distance(att[b, i], fastkit.exits_world[i], att[b, j],
                                          fastkit.exits_world[j], n=301)
                    assert res.distance[b, i, j] <= d + 1e-12 <= res.distance[b, i, j] + 0.03
            # brute force: points along the cable strictly inside the platform box
            seg = att[b, i] + s * (fastkit.exits_world[i] - att[b, i])
            loc = (seg - P[b, :3]) @ st_.R[b]                  # R^T (x - p)
            inside = np.all((loc > lo + 1e-6) & (loc < hi - 1e-6), axis=1)
            assert bool(inside.any()) == bool(res.cable_platform[b, i])
    assert res.cable_platform.any() and not res.cable_platform.all()
    np.testing.assert_array_equal(res.free, ~res.cable_cable & ~res.cable_platform.any(1))


def test_preset_crossing_cables_meet_at_level_poses(fastkit):
    """In the preset's assumed pattern each crossing pair (e.g. C11 and C22: exits at the
    same height and lateral offset, attachments too) spans a plane and crosses inside it
    at every level pose; a small yaw separates them."""
    res = cable_interference(fastkit, random_poses(fastkit, 20, seed=2, angle=0.0))
    k = [c.name for c in fastkit.cables]
    i, j = k.index("C11"), k.index("C22")
    np.testing.assert_allclose(res.distance[:, i, j], 0.0, atol=1e-9)
    assert res.cable_cable.all()
    yawed = cable_interference(fastkit, [[0.5, 0.0, 1.0, 0.0, 0.0, 0.05]])
    assert yawed.distance[0, i, j] > 1e-3


def test_cables_sharing_an_anchor_are_compared_beyond_it(point_mass):
    """Four cables share the point-mass attachment: the trimmed distance of every pair is
    2 l sin(theta / 2) (l = anchor_length, theta the angle between them), so they
    interfere exactly when that is below the cable diameter."""
    pose = np.array([[0.3, -0.2, 1.2]])
    st_ = cable_state(point_mass, pose)
    u = st_.unit[0]
    ell = 0.05
    res = cable_interference(point_mass, pose, anchor_length=ell)
    cos = np.clip(u @ u.T, -1, 1)
    expect = 2 * ell * np.sin(np.arccos(cos) / 2)
    off = ~np.eye(4, dtype=bool)
    np.testing.assert_allclose(res.distance[0][off], expect[off], rtol=1e-9)
    assert res.free[0]                         # in contact only at the shared point
    d_min = expect[off].min()
    assert not cable_interference(point_mass, pose, anchor_length=ell,
                                  min_distance=0.99 * d_min).cable_cable[0]
    assert cable_interference(point_mass, pose, anchor_length=ell,
                              min_distance=1.01 * d_min).cable_cable[0]


def test_shared_attachment_pairs_of_ipanema_match_sampling():
    """IPAnema 1 (CASPR) has four pairs of cables on a common attachment point: their
    distance equals brute-force sampling of the cables trimmed at the shared end."""
    from pathlib import Path

    from taut.io.caspr import load_caspr_model
    d = Path(__file__).resolve().parents[3] / "examples" / "cdpr" / "caspr"
    robot = load_caspr_model(d / "IPAnema_1_bodies.xml", d / "IPAnema_1_cables.xml")
    P = random_poses(robot, 4, seed=5, angle=0.3)
    ell = 0.1
    res = cable_interference(robot, P, anchor_length=ell)
    st_ = cable_state(robot, P)
    att = P[:, None, :3] + st_.r
    share = np.all(robot.attach_local[:, None] == robot.attach_local[None], axis=2)
    pairs = [(i, j) for i in range(robot.m) for j in range(i + 1, robot.m) if share[i, j]]
    assert len(pairs) == 4
    for b in range(len(P)):
        for i, j in pairs:
            a_i = att[b, i] + ell * st_.unit[b, i]
            a_j = att[b, j] + ell * st_.unit[b, j]
            # the 2001 x 2001 grid's minimum, row by row (the full grid was 2 s of CPU)
            sampled = _sampled_distance_rows(a_i, robot.exits_world[i], a_j,
                                             robot.exits_world[j], n=2001)
            assert res.distance[b, i, j] <= sampled + 1e-12
            assert sampled <= res.distance[b, i, j] + 0.01
            assert res.distance[b, i, j] > 0    # not interfering: they only meet at the ring
