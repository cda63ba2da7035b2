"""The sheet mesh (pure numpy): corners on the vertices, nodes in the sheet, tendon rest
lengths equal to flat distances, no tendon through a node."""

import numpy as np
from hypothesis import given, settings, strategies as st

from taut.physics._mesh import sheet_mesh
from taut.sheet import random_convex_polygon


@settings(max_examples=25, deadline=None)
@given(n=st.integers(3, 8), seed=st.integers(0, 10_000), divisions=st.integers(5, 12))
def test_mesh_invariants(n, seed, divisions):
    V = random_convex_polygon(n, np.random.default_rng(seed), radius=700.0)
    rng = np.random.default_rng(seed + 1)
    w = rng.dirichlet(np.ones(n))
    contact = w @ V
    m = sheet_mesh(V, divisions, contact=contact)
    np.testing.assert_allclose(m.nodes[m.corners], V, atol=1e-9)
    np.testing.assert_allclose(m.nodes[m.contact], contact, atol=1e-9)
    # Every node lies in the closed polygon (convex: on the inner side of every edge).
    e = np.roll(V, -1, axis=0) - V
    cross = e[:, 0] * (m.nodes[:, None, 1] - V[:, 1]) - e[:, 1] * (m.nodes[:, None, 0] - V[:, 0])
    sign = np.sign(np.sum(V[:, 0] * np.roll(V[:, 1], -1) - np.roll(V[:, 0], -1) * V[:, 1]))
    assert np.all(cross * sign >= -1e-6 * 700)
    np.testing.assert_allclose(m.rest, np.linalg.norm(m.nodes[m.pairs[:, 0]]
                                                      - m.nodes[m.pairs[:, 1]], axis=1))
    assert np.all(m.rest <= 4.5 * m.spacing * (1 + 1e-12))
    # No third node on a kept tendon's segment.
    a, b = m.nodes[m.pairs[:, 0]], m.nodes[m.pairs[:, 1]]
    for k in range(0, len(m.pairs), max(1, len(m.pairs) // 50)):
        d = b[k] - a[k]
        t = (m.nodes - a[k]) @ d / (d @ d)
        off = np.linalg.norm(m.nodes - a[k] - t[:, None] * d, axis=1)
        assert not np.any((t > 1e-6) & (t < 1 - 1e-6) & (off < 1e-3 * m.spacing))
    # Triangles cover the polygon: their areas add up to its area.
    p = m.nodes[m.triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    poly = 0.5 * abs(np.sum(V[:, 0] * np.roll(V[:, 1], -1) - np.roll(V[:, 0], -1) * V[:, 1]))
    np.testing.assert_allclose(area, poly, rtol=1e-9)


def test_spacing_follows_divisions():
    V = np.array([[0.0, 0.0], [1000.0, 0.0], [1000.0, 1000.0], [0.0, 1000.0]])
    coarse, fine = sheet_mesh(V, 7), sheet_mesh(V, 14)
    assert np.isclose(coarse.spacing, 2 * fine.spacing)
    assert 3 < len(fine.nodes) / len(coarse.nodes) < 5     # nodes ~ 1 / spacing^2
