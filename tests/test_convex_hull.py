"""taut._geometry: the one convex hull (the planner's compiled clearance, the cable robots'
support polygons, the squeezed formations, the app's outline) against shapely (GEOS) and
scipy (Qhull), independent implementations, on collinear, repeated and degenerate inputs
as well as generic ones."""

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from taut._geometry import convex_hull, convex_hull_2d

#: Points on a small integer grid, scaled by a power of two and shifted: every orientation
#: is computed exactly, and collinear and repeated points are frequent.
grid_points = st.tuples(
    st.lists(st.tuples(st.integers(-4, 4), st.integers(-4, 4)), min_size=0, max_size=14),
    st.integers(-3, 3), st.tuples(st.integers(-50, 50), st.integers(-50, 50)))


def _grid(drawn):
    pts, exp, shift = drawn
    return (np.array(pts, float).reshape(-1, 2) * 2.0 ** exp) + shift


def _vertex_set(geom) -> set[tuple[float, float]]:
    """The distinct vertices of shapely's hull (a Point, LineString or Polygon)."""
    if geom.is_empty:
        return set()
    coords = geom.exterior.coords if geom.geom_type == "Polygon" else geom.coords
    return {tuple(c) for c in np.asarray(coords)}


def _is_ccw_from_lowest(h: np.ndarray) -> bool:
    """Counter-clockwise (every turn strictly left), starting at the smallest (x, y)."""
    if len(h) < 3:
        return True
    e = np.roll(h, -1, axis=0) - h
    turns = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    first = min(range(len(h)), key=lambda i: (h[i, 0], h[i, 1]))
    return bool(np.all(turns > 0)) and first == 0


@settings(max_examples=400, deadline=None)
@given(grid_points)
def test_hull_is_shapely_hull_on_exact_inputs(drawn):
    """Same vertex set as GEOS's hull (no collinear or repeated vertex: GEOS drops them
    too), counter-clockwise from the lowest point, 1 vertex when every point coincides,
    the 2 ends when all lie on a line."""
    p = _grid(drawn)
    h = convex_hull_2d(p)
    want = _vertex_set(shapely.convex_hull(shapely.multipoints(p))) if len(p) else set()
    assert h.shape == (len(want), 2)
    assert {tuple(v) for v in h} == want
    assert _is_ccw_from_lowest(h)


@settings(max_examples=200, deadline=None)
@given(st.integers(3, 40), st.integers(0, 2**32 - 1), st.booleans())
def test_hull_is_qhull_hull_on_generic_points(n, seed, cluster):
    """Random points (some far from the origin, where rounding is coarse): Qhull's
    vertices, in Qhull's counter-clockwise order up to the first vertex."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-1, 1, (n, 2)) * (1e-3 if cluster else 1.0) + (1e3 if cluster else 0.0)
    h = convex_hull_2d(p)
    q = p[ConvexHull(p).vertices]
    assert len(h) == len(q)
    start = int(np.flatnonzero((q == h[0]).all(axis=1))[0])
    assert np.array_equal(np.roll(q, -start, axis=0), h)


@settings(max_examples=200, deadline=None)
@given(grid_points)
def test_kernel_is_the_wrapper_and_its_plain_python_fallback(drawn):
    """The kernel on unsorted points, with buffers of the documented size, writes the
    wrapper's hull; run as plain Python (the numpy fallback) it writes the same."""
    p = np.ascontiguousarray(_grid(drawn)[::-1])
    n = len(p)
    want = convex_hull_2d(p)
    kernels = [convex_hull] + ([convex_hull.py_func] if hasattr(convex_hull, "py_func") else [])
    for kernel in kernels:
        out = np.full((n + 1, 2), np.nan)
        m = kernel(p, np.empty(n, np.int64), out)
        assert m == len(want)
        assert np.array_equal(out[:m], want)


def test_degenerate_inputs():
    assert convex_hull_2d(np.zeros((0, 2))).shape == (0, 2)
    assert convex_hull_2d([[1.5, -2.0]]).tolist() == [[1.5, -2.0]]
    assert convex_hull_2d([[1.0, 1.0]] * 5).tolist() == [[1.0, 1.0]]
    assert convex_hull_2d([[2, 2], [0, 0], [1, 1], [0, 0], [2, 2]]).tolist() == [
        [0.0, 0.0], [2.0, 2.0]]
    # A point off the edge by one part in 1e13 is kept; one exactly on it is not.
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    assert len(convex_hull_2d(square + [[0.5, 0.0]])) == 4
    assert len(convex_hull_2d(square + [[0.5, -1e-13]])) == 5
