"""The FK fast paths agree with the general code they shortcut."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.errors import InfeasibleFormationError
from taut.sheet import Sheet, _lifted as _kernel, forward_kinematics, forward_kinematics_batch
from taut.sheet.fk import _numpy as fk_numpy, _solve as fk_solve
from taut.sheet.fk._candidates import hull_candidates, padded_small_subsets
from taut.sheet._lifted import Frame, reduced_hessian_min_eig, solve_candidates, solve_table
from taut.sheet import check_formation
from taut.sheet import random_scattered_team, random_team
from taut.sheet import SheetTeam

SETTINGS = settings(max_examples=30, deadline=None)


def team(seed, n):
    rng = np.random.default_rng(seed)
    return (random_scattered_team if seed % 2 else random_team)(n, rng)


def signature(result):
    return [(e.taut, e.kind) for e in result.equilibria]


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(4, 9), batch=st.integers(1, 6))
def test_solve_table_equals_solve_candidates(seed, n, batch):
    sheet, formation = team(seed, n)
    rng = np.random.default_rng(seed)
    forms = formation[None] + rng.normal(scale=1e-3 * sheet.size, size=(batch, n, 2))
    frame = Frame.build(sheet.vertices, forms, 2.0 * sheet.size, sheet.size)
    table = padded_small_subsets(n, sheet.has_collinear_vertices)
    a = solve_table(frame, table)
    b = solve_candidates(frame, np.repeat(np.arange(batch), len(table)),
                         np.tile(table, (batch, 1)))
    for f in ("form", "subset", "size", "source"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    np.testing.assert_allclose(a.x, b.x, atol=1e-12)
    np.testing.assert_allclose(a.w, b.w, atol=1e-9)
    half = solve_table(frame, table, slice(batch // 2, batch))
    np.testing.assert_array_equal(half.form, a.form[a.form >= batch // 2])
    # Per-size systems (used for large blocks) give the same solutions.
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernel, "PER_SIZE_MIN", 0)
        c = solve_table(frame, table)
    np.testing.assert_array_equal(c.source, a.source)
    np.testing.assert_allclose(c.x, a.x, atol=1e-11)
    np.testing.assert_allclose(c.w, a.w, atol=1e-8)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(7, 30))
def test_hull_curvature_equals_reduced_hessian(seed, n):
    sheet, formation = team(seed, n)
    frame = Frame.build(sheet.vertices, formation[None], 2.0 * sheet.size, sheet.size)
    st_ = hull_candidates(frame.P[0], False).stationary
    if st_ is None:
        return
    ref = reduced_hessian_min_eig(frame, st_.form, st_.subset)
    known = ~np.isnan(st_.curvature)
    assert np.all(np.isinf(st_.curvature[st_.size == 5]))
    np.testing.assert_allclose(st_.curvature[known], ref[known], rtol=0, atol=1e-8)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(7, 14))
def test_fast_equals_subsets_in_output_order(seed, n):
    """N <= 8 uses the subset table, larger teams the hull; both give the same list."""
    sheet, formation = team(seed, n)
    hold = 1.5 * sheet.size
    fast = forward_kinematics(SheetTeam(sheet, hold, mass=1.0), formation)
    subsets = forward_kinematics(SheetTeam(sheet, hold, mass=1.0), formation, method="subsets")
    assert signature(fast) == signature(subsets)
    for x, y in zip(fast.equilibria, subsets.equilibria):
        np.testing.assert_allclose(x.object, y.object, atol=1e-9 * sheet.size)
        if x.tensions is None or y.tensions is None:
            assert x.tensions is None and y.tensions is None and x.kind == "not_equilibrium"
        else:
            np.testing.assert_allclose(x.tensions, y.tensions, rtol=1e-6, atol=1e-9)


def test_batch_blocks_do_not_change_results(monkeypatch):
    sheet, formation = team(3, 6)
    rng = np.random.default_rng(1)
    forms = formation[None] + rng.normal(scale=2e-3 * sheet.size, size=(40, 6, 2))
    d = np.linalg.norm(forms[:, :, None] - forms[:, None], axis=3)
    forms = forms[np.all(d <= sheet.side_lengths(), axis=(1, 2))]
    whole = forward_kinematics_batch(SheetTeam(sheet, 2.0 * sheet.size), forms)
    monkeypatch.setattr(fk_solve, "TABLE_BLOCK", 7 * len(padded_small_subsets(6, False)))
    blocks = forward_kinematics_batch(SheetTeam(sheet, 2.0 * sheet.size), forms)
    np.testing.assert_array_equal(whole.count, blocks.count)
    np.testing.assert_array_equal(whole.taut, blocks.taut)
    np.testing.assert_array_equal(whole.kind, blocks.kind)
    np.testing.assert_allclose(whole.object, blocks.object, equal_nan=True)


def test_formation_check_fast_path_matches_model_check():
    sheet = Sheet.regular(5, 1.0)
    exact = sheet.vertices.copy()                      # every pair exactly at its limit
    np.testing.assert_array_equal(fk_numpy._formations(sheet, exact, "formation", True)[0][0],
                                  check_formation(sheet, exact))
    inside = 0.9 * exact
    np.testing.assert_array_equal(fk_numpy._formations(sheet, inside, "formation", True)[0][0],
                                  inside)
    torn = exact.copy()
    torn[0] *= 1.01
    with pytest.raises(InfeasibleFormationError) as fast_err:
        forward_kinematics(SheetTeam(sheet, 1.0), torn)
    with pytest.raises(InfeasibleFormationError) as model_err:
        check_formation(sheet, torn)
    assert fast_err.value.pair == model_err.value.pair
    assert str(fast_err.value) == str(model_err.value)
    batch = forward_kinematics_batch(SheetTeam(sheet, 1.0), np.stack([inside, torn]))
    assert batch.feasible.tolist() == [True, False] and batch.count[1] == 0
    assert model_err.value.problem in batch.message


def test_per_size_systems_with_collinear_vertices(monkeypatch):
    """Pairs (2-subsets) are candidates when sheet vertices are collinear."""
    sheet = Sheet([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert sheet.has_collinear_vertices
    rng = np.random.default_rng(4)
    forms = 0.9 * sheet.vertices[None] + rng.normal(scale=0.01, size=(30, 5, 2))
    whole = forward_kinematics_batch(SheetTeam(sheet, 1.5), forms)
    monkeypatch.setattr(_kernel, "PER_SIZE_MIN", 0)
    split = forward_kinematics_batch(SheetTeam(sheet, 1.5), forms)
    np.testing.assert_array_equal(whole.taut, split.taut)
    np.testing.assert_array_equal(whole.kind, split.kind)
    np.testing.assert_allclose(whole.object, split.object, equal_nan=True, atol=1e-12)
    single = [signature(forward_kinematics(SheetTeam(sheet, 1.5), f)) for f in forms]
    assert single == [signature(split.result(b)) for b in range(len(forms))]
