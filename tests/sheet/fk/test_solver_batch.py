"""The batch kernel (``_batch_kernel``: one workspace for the whole batch) gives the rows
of the per-formation kernel, and ``FKSolver.solve_batch`` the results of per-call
``solve``, on random and degenerate teams."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.sheet import FKSolver, Sheet
from taut._jit import HAVE_NUMBA
from taut.sheet import random_team
from taut.sheet import SheetTeam

pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")


def _batch(sheet, R, rng, kind):
    """Feasible formations near ``R``: jittered, shrunk, or (degenerate) exact and
    nearly exact similar copies of the sheet (all cables taut; the snapping path)."""
    B = 12
    if kind == "copies":
        c = sheet.vertices.mean(axis=0)
        s = rng.uniform(0.9, 1.0, B)[:, None, None]
        forms = (sheet.vertices - c) * s + c
        forms[::2] += rng.normal(scale=1e-9 * sheet.size, size=forms[::2].shape)
        return forms
    c = R.mean(axis=0)
    shrink = rng.uniform(0.85, 1.0, B)[:, None, None]
    forms = (R - c) * shrink + c
    if kind == "jitter":
        forms = forms + rng.normal(scale=0.003 * sheet.size, size=forms.shape) * shrink
    return forms


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 12),
       kind=st.sampled_from(["jitter", "shrink", "copies"]))
def test_solve_batch_equals_per_call_solve(seed, n, kind):
    from taut.sheet._kernels import batch as bk
    from taut.sheet._kernels import small as sk
    rng = np.random.default_rng(seed)
    sheet, R = random_team(n, rng)
    solver = FKSolver(SheetTeam(sheet, float(rng.uniform(0.5, 2.0)) * sheet.size, mass=2.0))
    forms = _batch(sheet, R, rng, kind)
    iu, ju = np.triu_indices(n, 1)
    d = np.linalg.norm(forms[:, iu] - forms[:, ju], axis=2)
    forms = np.ascontiguousarray(forms[np.all(d <= sheet.side_lengths()[iu, ju], axis=1)])
    if not len(forms):
        return
    a = sk.solve_formations(forms, *solver._args)
    b = bk.solve_formations_ws(forms, *solver._args)
    assert a[2] == b[2]
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    batch = solver.solve_batch(forms)
    for k in range(len(forms)):
        one = solver.solve(forms[k])
        got = batch.result(k).equilibria
        assert [(e.taut, e.kind) for e in got] == [(e.taut, e.kind) for e in one.equilibria]
        for x, y in zip(got, one.equilibria):
            np.testing.assert_allclose(x.object, y.object, rtol=0, atol=1e-12 * sheet.size)
            np.testing.assert_allclose(x.weights, y.weights, rtol=0, atol=1e-12)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("n", [4, 14])
def test_batch_with_a_torn_formation_flags_it(backend, n):
    """A torn formation is flagged in its row; the others get their own answers."""
    if backend == "numba" and not HAVE_NUMBA:
        pytest.skip("numba is not installed")
    sheet = Sheet.regular(n, 1.0)
    forms = np.stack([0.9 * sheet.vertices, 1.01 * sheet.vertices, 0.8 * sheet.vertices])
    solver = FKSolver(SheetTeam(sheet, 1.0, mass=2.0), backend=backend)
    batch = solver.solve_batch(forms)
    assert batch.feasible.tolist() == [True, False, True]
    assert batch.success.tolist() == [True, False, True]
    assert batch.status.tolist() == ["ok", "infeasible", "ok"] and batch.count[1] == 0
    assert "1 infeasible" in batch.message and "formation 1: robots" in batch.message
    for b in (0, 2):
        one = solver.solve(forms[b])
        got = batch.result(b)
        assert [(e.taut, e.kind) for e in got.equilibria] == \
            [(e.taut, e.kind) for e in one.equilibria]
        for x, y in zip(got.equilibria, one.equilibria):
            np.testing.assert_allclose(x.object, y.object, atol=1e-12)
            np.testing.assert_allclose(x.tensions, y.tensions, rtol=1e-12)
    everything_torn = solver.solve_batch(forms[1:2] * 1.1)
    assert everything_torn.count.tolist() == [0] and not everything_torn.success[0]


def test_batch_kernel_grows_its_output_and_stops_at_a_torn_formation():
    """More rows than the batch kernel's first output holds (``max(16, 2 B)``), then a torn
    formation: the rows and formation indices of the per-formation loop up to it, and its
    index (the kernel returns to grow its output and resumes where it stopped)."""
    from taut.sheet._kernels import batch as bk
    from taut.sheet._kernels import small as sk
    rng = np.random.default_rng(5)
    for _ in range(200):
        sheet, R = random_team(6, rng)
        solver = FKSolver(SheetTeam(sheet, 2.0 * sheet.size))
        k, _, _ = sk.solve_formation(R, *solver._args, np.empty((len(solver._table), 30)))
        if k >= 3:
            break
    assert k >= 3
    forms = np.repeat(R[None], 40, axis=0)
    forms[30] *= 3.0                               # torn: rows of 0..29 only, 30 flagged
    a = sk.solve_formations(forms, *solver._args)
    b = bk.solve_formations_ws(forms, *solver._args)
    assert a[2] == b[2] == 30
    assert len(b[0]) == 30 * k > 2 * len(forms)     # the output grew on the way
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    whole = bk.solve_formations_ws(np.ascontiguousarray(forms[:30]), *solver._args)
    assert whole[2] == -1 and np.array_equal(whole[0], b[0])



_FIELDS = ("count", "valid", "taut", "object", "contact", "weights", "tensions", "kind")


def _late_team(seed, mass):
    """A team of 4 and 40 formations jittered by 3 % of the sheet size: 1 to 3 states
    each (seed 6: all feasible, a stable state in each; seed 4: some torn, some without a
    stable state)."""
    rng = np.random.default_rng(seed)
    sheet, R = random_team(4, rng)
    hold = 1.5 * sheet.size
    solver = FKSolver(SheetTeam(sheet, hold, mass=mass) if mass else SheetTeam(sheet, hold))
    return solver, R + rng.normal(scale=0.03 * sheet.size, size=(40, 4, 2))


def _same_late(solver, forms, want):
    """A fresh batch result built lazily gives ``want``'s fields (read first there) when
    read after ``success``, and so does its pickled copy."""
    import pickle

    late = solver.solve_batch(forms)
    assert callable(late._enum)                    # nothing but the kinds copied yet
    success = late.success.copy()
    assert callable(late._enum)
    for r in (pickle.loads(pickle.dumps(late)), late):
        for f in _FIELDS + ("success", "status", "message"):
            if want[f] is None:
                assert getattr(r, f) is None
            else:
                np.testing.assert_array_equal(getattr(r, f), want[f])
        np.testing.assert_array_equal(r.success, success)


@pytest.mark.parametrize("mass", [None, 2.0])
def test_batch_arrays_read_late_or_pickled_are_the_kernel_rows(mass):
    """``batch_from_rows`` copies only the kinds out of the kernel rows at once, the other
    padded arrays when a field first needs them: read first, after ``success`` or after a
    pickle, they are the rows of each formation in order (padding NaN / False / -1)."""
    solver, forms = _late_team(6, mass)
    rows, form = solver._fix_batch(forms, *solver._kernel_batch(forms)[:2])
    first = solver.solve_batch(forms)
    want = {f: getattr(first, f) for f in _FIELDS + ("success", "status", "message")}
    K = want["kind"].shape[1]
    assert K == 3 and len(set(want["count"].tolist())) == 3 and want["success"].all()
    for b in range(len(forms)):
        mine = rows[form == b]
        c = len(mine)
        assert want["count"][b] == c
        np.testing.assert_array_equal(want["kind"][b], np.r_[mine[:, 0], [-1] * (K - c)])
        np.testing.assert_array_equal(want["valid"][b], np.arange(K) < c)
        np.testing.assert_array_equal(want["object"][b, :c], mine[:, 2:5])
        np.testing.assert_array_equal(want["contact"][b, :c], mine[:, 5:7])
        np.testing.assert_array_equal(want["taut"][b, :c], mine[:, 8:12] > 0.5)
        np.testing.assert_array_equal(want["weights"][b, :c], mine[:, 12:16])
        assert np.isnan(want["object"][b, c:]).all() and not want["taut"][b, c:].any()
    assert (want["tensions"] is None) == (mass is None)
    _same_late(solver, forms, want)


def test_batch_arrays_read_late_with_torn_and_unheld_formations():
    """As above on a batch with torn formations and formations without a stable state
    (the direct minimisation's candidates)."""
    solver, forms = _late_team(4, 2.0)
    first = solver.solve_batch(forms)
    want = {f: getattr(first, f) for f in _FIELDS + ("success", "status", "message")}
    assert not want["success"].all() and not first.feasible.all()
    _same_late(solver, forms, want)
