"""The compiled small-team kernel (numba) and the numpy path give the same equilibria.

Two independent implementations of the same decisions (Lagrange systems by hand-written
LU vs LAPACK, the reduced Hessian by closed forms vs SVD, ...), compared on generic,
scattered and degenerate teams: formations that are (nearly) similar copies of the sheet
(the FK paper's Lemma 2), robot pairs exactly at their sheet distance, sheets with
collinear vertices, low hold heights.
"""


import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from taut.sheet import FKSolver, Sheet
from taut.sheet import random_convex_polygon, random_scattered_team, random_team
from taut.sheet import SheetTeam
from taut.sheet._tol import BACKEND_RTOL, BACKEND_WEIGHT_TOL

pytest.importorskip("numba")

KINDS = ("convex", "scattered", "near_copy", "exact_copy", "pair_at_limit", "collinear",
         "collinear_robots", "coincident", "regular")


def make_team(kind, seed, n):
    """A (sheet, formation) pair of the given kind (all feasible)."""
    rng = np.random.default_rng(seed)
    if kind == "convex":
        return random_team(n, rng)
    if kind == "scattered":
        return random_scattered_team(n, rng)
    if kind == "collinear":
        # A convex polygon with a vertex inserted in the middle of each of a few edges.
        base = random_convex_polygon(max(3, n - n // 3), rng)
        pts = []
        for i, p in enumerate(base):
            pts.append(p)
            if len(pts) + (len(base) - i - 1) < n:
                pts.append(0.5 * (p + base[(i + 1) % len(base)]))
        V = np.array(pts[:n]) if len(pts) >= n else np.array(pts)
        sheet = Sheet(V)
        R = _shrunk_copy(sheet.vertices, rng, rng.uniform(0.6, 0.95), 0.02)
        return sheet, R
    if kind == "collinear_robots":
        # Robots (nearly) on a line: the lifted points lose a dimension.
        sheet = Sheet(random_convex_polygon(n, rng))
        t = np.sort(rng.uniform(-1, 1, n))
        line = np.column_stack([t, 10.0 ** -rng.uniform(3, 16) * rng.normal(size=n)])
        return sheet, _fit_inside(sheet.vertices, line, rng)
    if kind == "coincident":
        # Two or more robots (nearly) on top of each other.
        sheet, R = random_team(n, rng)
        k = int(rng.integers(2, n + 1))
        R = R.copy()
        R[1:k] = R[0] + 10.0 ** -rng.uniform(4, 16) * rng.normal(size=(k - 1, 2))
        return sheet, _fit_inside(sheet.vertices, R, rng)
    if kind == "regular":
        # A regular polygon held by a scaled, rotated regular polygon (Lemma 2 exactly,
        # in the rounding of cos and sin), possibly a little perturbed.
        sheet = Sheet.regular(n, rng.uniform(0.5, 3.0))
        R = _shrunk_copy(sheet.vertices, rng, rng.uniform(0.4, 0.95),
                         float(rng.choice([0.0, 1e-12, 1e-9, 1e-6])))
        return sheet, R
    if kind in ("near_copy", "exact_copy"):
        # Cocircular vertices: a similar copy puts every lifted point on one 2-plane.
        t = 2 * np.pi * np.arange(n) / n + rng.uniform(-0.3, 0.3, n) * (2 * np.pi / n)
        sheet = Sheet(np.column_stack([np.cos(t), np.sin(t)]))
    else:
        sheet = Sheet(random_convex_polygon(n, rng))
    V = sheet.vertices
    if kind == "near_copy":
        eps = 10.0 ** -rng.uniform(4, 13)
        return sheet, _shrunk_copy(V, rng, rng.uniform(0.5, 1.0) * (1 - eps), eps)
    if kind == "exact_copy":                   # a similar copy: Lemma 2 exactly
        return sheet, _shrunk_copy(V, rng, rng.uniform(0.5, 0.95), 0.0)
    # pair_at_limit: a random formation scaled until its tightest pair is taut.
    _, R = random_team(n, rng)
    R = R - R.mean(axis=0)
    iu, ju = np.triu_indices(n, 1)
    ratio = (np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(R[iu] - R[ju], axis=1))
    return sheet, R * ratio.min() + rng.normal(size=2)


def _fit_inside(V, R, rng):
    """``R`` scaled (about its centroid) until no pair exceeds its sheet distance, shifted
    at random."""
    R = R - R.mean(axis=0)
    iu, ju = np.triu_indices(len(V), 1)
    dr = np.linalg.norm(R[iu] - R[ju], axis=1)
    ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.maximum(dr, 1e-300)
    return R * min(1.0, ratio.min()) * rng.uniform(0.5, 1.0) + rng.normal(size=2)


def _shrunk_copy(V, rng, scale, noise):
    """A rotated, shifted copy of the vertices scaled by ``scale``, moved by ``noise``
    (relative) at random without exceeding any sheet distance."""
    t = rng.uniform(0, 2 * np.pi)
    Q = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    R = scale * (V - V.mean(axis=0)) @ Q.T
    size = np.max(np.linalg.norm(V - V.mean(axis=0), axis=1))
    R = R + noise * size * rng.uniform(-1, 1, R.shape)
    iu, ju = np.triu_indices(len(V), 1)
    ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(R[iu] - R[ju], axis=1)
    if ratio.min() < 1.0:
        R = R * ratio.min()
    return R + rng.normal(size=2)


def assert_same(a, b, size):
    """Same taut sets and kinds, in the same order; equilibria (stable, saddle) at the
    same place within ``BACKEND_RTOL`` of the sheet size with the same load shares (within
    ``BACKEND_WEIGHT_TOL``). Non-equilibria near Lemma 2 can have weights ~1e5 (their
    systems' condition number), where rounding differences are amplified by that much:
    only their positions are compared, with a tolerance growing with the largest weight
    and ten times the equilibria's (near_copy seed 601, n 8, hold 0.3: weights 3.5e4,
    positions 1.1e-9 x weight x size apart)."""
    sig_a = [(e.taut, e.kind) for e in a.equilibria]
    sig_b = [(e.taut, e.kind) for e in b.equilibria]
    assert sig_a == sig_b
    worst = 0.0
    for ea, eb in zip(a.equilibria, b.equilibria):
        c = 1.0 if eb.is_equilibrium else 10.0 * max(1.0, float(np.abs(eb.weights).max()))
        atol = BACKEND_RTOL * size * c
        np.testing.assert_allclose(ea.object, eb.object, rtol=0, atol=atol)
        np.testing.assert_allclose(ea.contact, eb.contact, rtol=0, atol=atol)
        np.testing.assert_allclose(ea.cable_lengths, eb.cable_lengths, rtol=0, atol=atol)
        if eb.is_equilibrium:
            np.testing.assert_allclose(ea.weights, eb.weights, rtol=0, atol=BACKEND_WEIGHT_TOL)
            # Tensions are load shares times the weight (N): a slack cable's 1e-10 share
            # is ~1e-9 N, so the absolute tolerance scales with the largest tension.
            force = max(1.0, float(np.abs(eb.tensions).max()))
            np.testing.assert_allclose(ea.tensions, eb.tensions, rtol=BACKEND_WEIGHT_TOL,
                                       atol=BACKEND_WEIGHT_TOL * force)
            worst = max(worst, float(np.abs(ea.object - eb.object).max()) / size)
        else:
            assert (ea.tensions is None) == (eb.tensions is None)
    return worst


def compare(kind, seed, n, hold_ratio, method="fast"):
    sheet, R = make_team(kind, seed, n)
    hold = hold_ratio * sheet.size
    team = SheetTeam(sheet, hold, mass=1.5)
    compiled = FKSolver(team, method=method, backend="numba")
    numpy_ = FKSolver(team, method=method, backend="numpy")
    a = compiled.solve(R)
    b = numpy_.solve(R)
    assert_same(a, b, sheet.size)
    return a


TEAMS = dict(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1),
             n=st.integers(3, 12), hold_ratio=st.sampled_from([0.3, 0.7, 1.0, 2.0, 5.0]))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(**TEAMS)
def test_compiled_equals_numpy(kind, seed, n, hold_ratio):
    compare(kind, seed, n, hold_ratio)


@pytest.mark.slow
@settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(**TEAMS)
def test_compiled_equals_numpy_thousands(kind, seed, n, hold_ratio):
    compare(kind, seed, n, hold_ratio)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(13, 22),
       method=st.sampled_from(["fast", "subsets"]))
def test_compiled_equals_numpy_on_larger_teams_many(kind, seed, n, method):
    compare(kind, seed, n, 2.0, method=method)


@settings(max_examples=12, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(13, 22),
       method=st.sampled_from(["fast", "subsets"]))
def test_compiled_equals_numpy_on_larger_teams(kind, seed, n, method):
    """Larger teams: the kernel on every subset ("subsets") or on the upper-hull faces
    ("fast") gives the numpy path's answers for the same method, degenerate kinds
    included (next to a similar copy both answer the copy)."""
    compare(kind, seed, n, 2.0, method=method)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("n", [15, 18, 22])
def test_fast_equals_subsets_next_to_a_similar_copy(seed, n):
    """Near Lemma 2 above 14 robots "fast" once found 21 stable states where "subsets"
    found 40 (near_copy, seed 0, n 22): all one physical state (objects within 1.1e-8 of
    the sheet size, formation 1e-10 from a similar copy). Both now answer the copy."""
    sheet, R = make_team("near_copy", seed, n)
    hold = 2.0 * sheet.size
    team = SheetTeam(sheet, hold, mass=1.0)
    fast = FKSolver(team, method="fast").solve(R)
    subsets = FKSolver(team, method="subsets").solve(R)
    assert fast.stable
    assert_same(fast, subsets, sheet.size)


@settings(max_examples=20, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8),
       batch=st.integers(1, 5))
def test_compiled_batch_equals_numpy_batch(kind, seed, n, batch):
    sheet, R = make_team(kind, seed, n)
    rng = np.random.default_rng(seed)
    forms = R[None] * rng.uniform(0.97, 1.0, (batch, 1, 1))
    hold = 1.5 * sheet.size
    team = SheetTeam(sheet, hold, mass=2.0)
    a = FKSolver(team, backend="numba").solve_batch(forms)
    b = FKSolver(team, backend="numpy").solve_batch(forms)
    np.testing.assert_array_equal(a.count, b.count)
    np.testing.assert_array_equal(a.taut, b.taut)
    np.testing.assert_array_equal(a.kind, b.kind)
    eq = (a.kind == 0) | (a.kind == 1)
    np.testing.assert_allclose(a.object[eq], b.object[eq], rtol=0, atol=1e-9 * sheet.size)
    np.testing.assert_allclose(a.weights[eq], b.weights[eq], rtol=0, atol=1e-7)
    for k in range(batch):
        assert_same(a.result(k), b.result(k), sheet.size)
        assert_same(a.result(k), FKSolver(team, backend="numba").solve(forms[k]), sheet.size)


def test_degenerate_kinds_reach_their_special_cases():
    """The generator really produces the degenerate cases: all-taut Lemma 2 states for
    similar copies of the sheet (FK paper Lemma 2), a stable state for near copies."""
    all_taut = near = 0
    for seed in range(10):
        res = compare("exact_copy", seed, 5, 2.0)
        all_taut += any(len(e.taut) == 5 for e in res.stable)
        near += bool(compare("near_copy", seed, 6, 2.0).stable)
    assert all_taut == 10
    assert near == 10


@settings(max_examples=60, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12),
       mirror=st.booleans())
def test_similar_fit_equals_similar_copy(kind, seed, n, mirror):
    """The compiled snap screen (closed-form 2-D Procrustes) matches the SVD fit."""
    from taut.sheet._kernels import small as sk
    from taut.sheet.fk._similar import similar_copy

    if kind in ("collinear_robots", "coincident"):
        kind = "convex"      # (nearly) singular cross-covariance: rotation vs reflection is noise
    sheet, R = make_team(kind, seed, n)
    if mirror:
        R = np.ascontiguousarray(R[:, ::-1])
    A = np.ascontiguousarray(sheet.vertices - sheet.vertices.mean(axis=0))
    scale, dist = sk.similar_fit(np.ascontiguousarray(R), A)
    _, scales, dists = similar_copy(sheet.vertices, R[None])
    if np.isinf(dists[0]):
        assert np.isinf(dist)
    else:
        assert dist == pytest.approx(dists[0], rel=1e-9, abs=1e-12 * sheet.size)
        assert scale == pytest.approx(scales[0], rel=1e-12)


def test_kernel_is_cached_on_disk():
    """numba's on-disk cache holds the per-call kernel (index files next to it or in
    NUMBA_CACHE_DIR); where the cache goes on a read-only install is tests/test_jit.py's."""
    import os

    from taut._jit import cache_dir
    from taut.sheet._kernels import small as _small_kernel

    sheet = Sheet.regular(4, 1.0)
    FKSolver(SheetTeam(sheet, 1.0)).solve(0.8 * sheet.vertices)
    places = (cache_dir()[0], os.path.join(os.path.dirname(_small_kernel.__file__), "__pycache__"))
    index = [f for where in places for _, _, files in os.walk(where) for f in files
             if f.startswith("batch.solve_one") and f.endswith(".nbi")]
    assert index
