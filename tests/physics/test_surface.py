"""Surface helpers: point-triangle distance against dense sampling; the point below."""

import numpy as np
from hypothesis import given, settings, strategies as st

from taut.physics._surface import point_triangle_distance, surface_below


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 100_000))
def test_distance_matches_sampling(seed):
    rng = np.random.default_rng(seed)
    A, B, C = rng.normal(size=(3, 1, 3))
    p = rng.normal(size=3) * 2
    u, v = np.meshgrid(np.linspace(0, 1, 301), np.linspace(0, 1, 301))
    keep = u + v <= 1
    pts = A + u[keep][:, None] * (B - A) + v[keep][:, None] * (C - A)
    sampled = np.min(np.linalg.norm(pts - p, axis=1))
    exact = point_triangle_distance(p, A, B, C)[0]
    assert exact <= sampled + 1e-12
    assert sampled - exact <= 0.02 * max(np.linalg.norm(B - A), np.linalg.norm(C - A))


def test_surface_below_in_a_cone():
    # A square pyramid pointing down, apex at the origin, edges at 45 degrees.
    nodes = np.array([[0, 0, 0], [1, 0, 1], [0, 1, 1], [-1, 0, 1], [0, -1, 1]], dtype=float)
    tri = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    z, _, bary = surface_below(nodes, tri, np.array([0.1, 0.1, 5.0]))
    assert np.isclose(z, 0.2) and np.isclose(bary.sum(), 1.0)
    assert surface_below(nodes, tri, np.array([3.0, 3.0, 5.0])) is None
