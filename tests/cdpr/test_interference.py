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
