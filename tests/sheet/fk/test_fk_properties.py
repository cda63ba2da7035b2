"""Cross-checks between FK algorithms and invariances of the solution set."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.sheet import Sheet, forward_kinematics, forward_kinematics_batch
from taut.sheet import random_scattered_team, random_team
from taut.sheet import SheetTeam
from taut.sheet._tol import SNAP_TOL

SETTINGS = settings(max_examples=40, deadline=None)


def team(seed, n, hold=None):
    """Random feasible team; odd seeds scatter the robots (not in convex position)."""
    rng = np.random.default_rng(seed)
    sheet, formation = (random_scattered_team if seed % 2 else random_team)(n, rng)
    hold = rng.uniform(0.4, 1.5) if hold is None else hold
    return sheet, formation, hold


def signature(result):
    return sorted((e.taut, e.kind) for e in result.equilibria)


def assert_same(a, b, scale, atol=1e-9):
    assert signature(a) == signature(b)
    for x, y in zip(sorted(a.equilibria, key=lambda e: e.taut),
                    sorted(b.equilibria, key=lambda e: e.taut)):
        np.testing.assert_allclose(x.object, y.object, atol=atol * scale)
        np.testing.assert_allclose(x.contact, y.contact, atol=atol * scale)
        # Weights far above 1 only occur in ill-conditioned non-equilibria (|w| ~ 1e3 near
        # Lemma 2), whose systems amplify rounding by their condition number (~|w|^2):
        # the compiled and LAPACK solves then differ by more than 1e-7 (both are ~1e-4
        # from the exact solution of the rounded data). Equilibria have 0 <= w <= 1.
        c = 1.0 if y.is_equilibrium else max(1.0, float(np.abs(y.weights).max()))
        np.testing.assert_allclose(x.weights, y.weights, atol=1e-7 * c * c)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 10))
def test_fast_equals_exhaustive_and_subsets(seed, n):
    sheet, formation, hold = team(seed, n)
    fast = forward_kinematics(SheetTeam(sheet, hold), formation)
    exhaustive = forward_kinematics(SheetTeam(sheet, hold), formation, method="exhaustive")
    subsets = forward_kinematics(SheetTeam(sheet, hold), formation, method="subsets")
    assert_same(fast, exhaustive, sheet.size)
    assert_same(fast, subsets, sheet.size)
    assert exhaustive.funnel.force_closure == len(exhaustive.equilibria)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(11, 30))
def test_fast_equals_subsets_larger_teams(seed, n):
    sheet, formation, hold = team(seed, n)
    held = SheetTeam(sheet, hold)
    assert_same(forward_kinematics(held, formation),
                forward_kinematics(held, formation, method="subsets"), sheet.size)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12))
def test_equilibria_are_stationary_and_weights_exact(seed, n):
    sheet, formation, hold = team(seed, n)
    r = forward_kinematics(SheetTeam(sheet, hold), formation)
    V = sheet.vertices
    for e in r.equilibria:
        t = np.array(e.taut)
        np.testing.assert_allclose(e.weights.sum(), 1.0, atol=1e-9)
        np.testing.assert_allclose(e.weights @ formation[t], e.object[:2], atol=1e-9 * sheet.size)
        np.testing.assert_allclose(e.weights @ V[t], e.contact, atol=1e-9 * sheet.size)
        assert 0 < e.object[2] < hold
        assert (e.kind == "not_equilibrium") == bool(np.any(e.weights < -1e-9))


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12),
       angle=st.floats(-np.pi, np.pi), shift=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_rigid_motion_of_formation(seed, n, angle, shift):
    """Rotating/translating the robots moves every object position the same way."""
    sheet, formation, hold = team(seed, n)
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    moved = formation @ rot.T + shift
    a = forward_kinematics(SheetTeam(sheet, hold), formation)
    b = forward_kinematics(SheetTeam(sheet, hold), moved)
    assert signature(a) == signature(b)
    for x, y in zip(a.equilibria, b.equilibria):
        np.testing.assert_allclose(rot @ x.object[:2] + shift, y.object[:2], atol=1e-8 * sheet.size)
        np.testing.assert_allclose(x.object[2], y.object[2], atol=1e-8 * sheet.size)
        np.testing.assert_allclose(x.contact, y.contact, atol=1e-8 * sheet.size)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12),
       angle=st.floats(-np.pi, np.pi), shift=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_rigid_motion_of_sheet(seed, n, angle, shift):
    """Moving the sheet's frame moves only the contact points."""
    sheet, formation, hold = team(seed, n)
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    a = forward_kinematics(SheetTeam(sheet, hold), formation)
    b = forward_kinematics(SheetTeam(Sheet(sheet.vertices @ rot.T + shift), hold), formation)
    assert signature(a) == signature(b)
    for x, y in zip(a.equilibria, b.equilibria):
        np.testing.assert_allclose(x.object, y.object, atol=1e-8 * sheet.size)
        np.testing.assert_allclose(rot @ x.contact + shift, y.contact, atol=1e-8 * sheet.size)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12), k=st.integers(1, 11),
       mirror=st.booleans())
def test_relabelling_robots(seed, n, k, mirror):
    """Cyclic relabelling (and reversing the order) permutes the taut sets only."""
    sheet, formation, hold = team(seed, n)
    perm = np.roll(np.arange(n), k % n)
    if mirror:
        perm = perm[::-1]
    a = forward_kinematics(SheetTeam(sheet, hold), formation)
    b = forward_kinematics(SheetTeam(Sheet(sheet.vertices[perm]), hold), formation[perm])
    inv = np.argsort(perm)
    mapped = sorted((tuple(sorted(inv[list(e.taut)].tolist())), e.kind) for e in a.equilibria)
    assert mapped == signature(b)
    key = {tuple(sorted(inv[list(e.taut)].tolist())): e for e in a.equilibria}
    for e in b.equilibria:
        np.testing.assert_allclose(key[e.taut].object, e.object, atol=1e-8 * sheet.size)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12),
       scale=st.floats(1e-3, 1e4))
def test_uniform_scaling(seed, n, scale):
    """Scaling every length scales the positions and keeps weights and kinds."""
    sheet, formation, hold = team(seed, n)
    a = forward_kinematics(SheetTeam(sheet, hold, mass=1.0), formation)
    b = forward_kinematics(SheetTeam(Sheet(sheet.vertices * scale), hold * scale, mass=1.0),
                           formation * scale)
    assert signature(a) == signature(b)
    for x, y in zip(a.equilibria, b.equilibria):
        np.testing.assert_allclose(x.object * scale, y.object, rtol=1e-8, atol=1e-8 * scale)
        np.testing.assert_allclose(x.weights, y.weights, atol=1e-8)
        if x.kind == "not_equilibrium":
            assert x.tensions is None and y.tensions is None
        else:
            np.testing.assert_allclose(x.tensions, y.tensions, rtol=1e-7, atol=1e-9)


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 14), batch=st.integers(1, 6))
def test_batch_equals_single(seed, n, batch):
    rng = np.random.default_rng(seed)
    sheet, formation = random_team(n, rng)
    forms = np.stack([formation + rng.normal(scale=0.002, size=formation.shape) * (b > 0)
                      for b in range(batch)])
    forms = np.stack([f if _feasible(sheet, f) else formation for f in forms])
    res = forward_kinematics_batch(SheetTeam(sheet, 0.8, mass=2.0), forms)
    for b in range(batch):
        single = forward_kinematics(SheetTeam(sheet, 0.8, mass=2.0), forms[b])
        assert_same(res.result(b), single, sheet.size)
        assert res.count[b] == len(single.equilibria)
        np.testing.assert_array_equal(res.stable[b, :res.count[b]], [e.stable for e in single.equilibria])


def _feasible(sheet, f):
    d = np.linalg.norm(f[:, None] - f[None], axis=2)
    return np.all(d <= sheet.side_lengths() + 1e-12)


@pytest.mark.parametrize("delta", [1e-7, 1e-4, 1e-2])
def test_near_degenerate_octagon(delta):
    """Perturbations of Lemma 2's configuration: every method agrees."""
    rng = np.random.default_rng(7)
    sheet = Sheet.regular(8, 0.9)
    t = 2 * np.pi * np.arange(8) / 8
    formation = 0.5 * np.column_stack([np.cos(t), np.sin(t)])
    formation = formation * (1 - delta * rng.uniform(0, 1, (8, 1)))
    fast = forward_kinematics(SheetTeam(sheet, 1.0), formation)
    exhaustive = forward_kinematics(SheetTeam(sheet, 1.0), formation, method="exhaustive")
    assert any(e.stable for e in fast.equilibria)
    if delta * 0.5 <= SNAP_TOL * sheet.size:
        # Within SNAP_TOL of a similar copy "fast" answers the copy (the Lemma 2 state,
        # every cable taut; docs/sheet_fk_solver.md): the same place as the paper's
        # algorithm on the formation itself, to that tolerance.
        assert [(e.taut, e.kind) for e in fast.equilibria] == [(tuple(range(8)), "stable")]
        np.testing.assert_allclose(fast.stable[0].object, exhaustive.stable[0].object,
                                   rtol=0, atol=SNAP_TOL * sheet.size)
    else:
        assert_same(fast, exhaustive, 1.0, atol=1e-7)


def test_square_sheet_on_square_formation():
    """The FK paper's Fig. 3: square on square, k = 4 but rank 2: one all-taut state."""
    sheet = Sheet([[0, 0], [1, 0], [1, 1], [0, 1]])
    formation = np.array([[0.2, 0.2], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]])
    for method in ("fast", "exhaustive"):
        r = forward_kinematics(SheetTeam(sheet, 1.0), formation, method=method)
        assert [e.taut for e in r.equilibria] == [(0, 1, 2, 3)]
        np.testing.assert_allclose(r.equilibria[0].object[:2], [0.5, 0.5], atol=1e-12)
        assert r.equilibria[0].stable


def test_robot_holding_mid_edge():
    """Collinear sheet vertices (a robot at the middle of a side) are supported."""
    sheet = Sheet([[0, 0], [0.5, 0], [1, 0], [1, 1], [0, 1]])
    assert sheet.has_collinear_vertices
    formation = np.array([[0.2, 0.2], [0.5, 0.15], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]])
    a = forward_kinematics(SheetTeam(sheet, 1.0), formation)
    b = forward_kinematics(SheetTeam(sheet, 1.0), formation, method="exhaustive")
    assert_same(a, b, 1.0)
    assert a.lowest is not None


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(6, 10))
def test_hull_path_equals_exhaustive_on_small_teams(seed, n):
    """Force the convex-hull path (normally used from 9 robots up) on small teams."""
    from taut.sheet.fk import _solve as fk_module

    sheet, formation, hold = team(seed, n)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(fk_module, "SMALL_TEAM", 3)
        fast = forward_kinematics(SheetTeam(sheet, hold), formation)
    assert_same(fast, forward_kinematics(SheetTeam(sheet, hold), formation, method="exhaustive"),
                sheet.size)
