"""The compiled branch follower (``_step_kernel``) against the numpy tracker: the same
supports accepted or rejected with the same states, and whole simulations (``simulate``
and the stepping ``Simulator``) through taut-set changes and jumps giving the same taut
sets, events and positions."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.io.trajectory import load_trajectory
from taut.sheet import Sheet, Simulator, forward_kinematics
from taut.sheet.sim._branch import Tracker, solve_support_one, solve_taut_sets
from taut._jit import HAVE_NUMBA
from taut.sheet import random_team
from taut.sheet import simulate
from taut.sheet import SheetTeam

EXAMPLES = Path(__file__).resolve().parents[3] / "examples/sheet/trajectories"
pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")


def team(n, rng):
    while True:
        sheet, R = random_team(n, rng)
        if forward_kinematics(SheetTeam(sheet, 1.0), R).stable:
            return sheet, R


def keyframes(sheet, R0, rng, segments, steps, amp):
    """Straight segments between random feasible formations (taut-set changes, jumps)."""
    keys = [R0]
    iu, ju = np.triu_indices(len(R0), 1)
    V = sheet.vertices
    for _ in range(segments):
        Q = keys[-1] + rng.normal(scale=amp, size=R0.shape)
        ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(Q[iu] - Q[ju], axis=1)
        c = Q.mean(axis=0)
        keys.append((Q - c) * min(1.0, 0.98 * ratio.min()) + c)
    s = np.linspace(0, 1, steps, endpoint=False)[:, None, None]
    return np.concatenate([(1 - s) * a + s * b for a, b in zip(keys[:-1], keys[1:])])


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(3, 8),
       zoom=st.sampled_from([1e-3, 1.0, 1e3]))
def test_compiled_support_solve_matches_numpy(seed, n, zoom):
    """Every 3..5-cable support of a random formation (and of one shrunk towards its
    centre, where other sets hold): accepted by the compiled solve exactly when by both
    numpy solves, with the same state (1e-9 of the sheet size) and exact taut set."""
    rng = np.random.default_rng(seed)
    sheet, R = random_team(n, rng)
    sheet = type(sheet)(sheet.vertices * zoom)
    R = R * zoom
    z = 1.0 * zoom
    tracker = Tracker(SheetTeam(sheet, z), compiled=True)
    sets = [c for k in (3, 4, 5) for c in itertools.combinations(range(n), k)][:60]
    idx = np.full((len(sets), 5), -1, dtype=np.intp)
    for r, c in enumerate(sets):
        idx[r, :len(c)] = c
    for Rf in (R, 0.97 * (R - R.mean(axis=0)) + R.mean(axis=0)):
        valid, ro, vo, zo, w, tight = solve_taut_sets(sheet, Rf[None], z,
                                                      np.zeros(len(sets), np.intp), idx)
        for r, c in enumerate(sets):
            k, (_, cro, cvo, czo, cw, ctight) = tracker.follow(_state(c, n), Rf[None])
            one = solve_support_one(tracker._Xv, tracker._v_centre, sheet.size, z, Rf, c)
            assert bool(k) == bool(valid[r]) == (one is not None), c
            if not k:
                continue
            tol = 1e-9 * sheet.size
            np.testing.assert_allclose(cro[0], ro[r], atol=tol)
            np.testing.assert_allclose(cvo[0], vo[r], atol=tol)
            np.testing.assert_allclose(czo[0], zo[r], atol=tol)
            np.testing.assert_allclose(cw[0], w[r], atol=1e-9)
            np.testing.assert_array_equal(ctight[0], tight[r])
            np.testing.assert_array_equal(ctight[0], one[4])
            np.testing.assert_allclose(cro[0], one[0], atol=tol)


def _state(support, n):
    from taut.sheet.sim._branch import State
    return State(tuple(support), tuple(support), np.zeros(2), np.zeros(2), 0.0, np.zeros(n))


def _same_run(a, b, size):
    """Two SimulationResults agree: taut sets, events, positions within 1e-9 of size."""
    assert a.taut == b.taut
    assert [(e.kind, e.step) for e in a.events] == [(e.kind, e.step) for e in b.events]
    np.testing.assert_allclose(a.object, b.object, atol=1e-9 * size)
    np.testing.assert_allclose(a.contact, b.contact, atol=1e-9 * size)
    np.testing.assert_allclose(a.weights, b.weights, atol=1e-8)
    assert (a.success, a.status) == (b.success, b.status)


# ~5 s of CPU: the slow target (CI runs it); test_key_frames_exercise_taut_changes_and_jumps
# keeps both engines compared on fixed key-frame runs (both event kinds) in the fast suite.
@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(3, 7), amp=st.floats(0.05, 0.3))
def test_compiled_simulation_matches_numpy_on_key_frames(seed, n, amp):
    """simulate and the stepping Simulator, compiled and numpy, on key-frame trajectories
    (straight moves between random formations: taut-set changes and jumps)."""
    rng = np.random.default_rng(seed)
    sheet, R0 = team(n, rng)
    R = keyframes(sheet, R0, rng, 3, 40, amp)
    fast = simulate(SheetTeam(sheet, 1.0), R, backend="numba")
    slow = simulate(SheetTeam(sheet, 1.0), R, backend="numpy")
    _same_run(fast, slow, sheet.size)
    sims = [Simulator(SheetTeam(sheet, 1.0), R[0], backend=b) for b in ("numba", "numpy")]
    for t in range(1, len(R)):
        a, b = (s.step(R[t]) for s in sims)
        assert a.taut == b.taut and a.status == b.status
        assert [(e.kind, e.step) for e in a.events] == [(e.kind, e.step) for e in b.events]
        np.testing.assert_allclose(a.object, b.object, atol=1e-9 * sheet.size)
        np.testing.assert_allclose(a.object, fast.object[t], atol=1e-9 * sheet.size)
        assert a.taut == fast.taut[t]


def test_key_frames_exercise_taut_changes_and_jumps():
    """The agreement above covers events: fixed key-frame runs with both kinds, stepped
    by velocities (the control-loop path) in both engines."""
    rng = np.random.default_rng(21)
    kinds: set[str] = set()
    for n in (4, 5, 6):
        sheet, R0 = team(n, rng)
        R = keyframes(sheet, R0, rng, 4, 50, 0.25)
        fast = simulate(SheetTeam(sheet, 1.0), R, backend="numba")
        _same_run(fast, simulate(SheetTeam(sheet, 1.0), R, backend="numpy"), sheet.size)
        kinds |= {e.kind for e in fast.events}
        dt = 0.1
        sims = [Simulator(SheetTeam(sheet, 1.0), R[0], backend=b, dt=dt)
                for b in ("numba", "numpy")]
        for t in range(1, len(R)):
            v = (R[t] - R[t - 1]) / dt
            a, b = (s.step(velocities=v) for s in sims)
            assert a.taut == b.taut and a.status == b.status
            assert [e.kind for e in a.events] == [e.kind for e in b.events]
            np.testing.assert_allclose(a.object, b.object, atol=1e-9 * sheet.size)
    # The square-sheet jump scenario of the examples (a branch ends: the object rolls).
    R = load_trajectory(EXAMPLES / "square4_jump.csv").formations
    square = Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]])
    fast = simulate(SheetTeam(square, 1.5), R, backend="numba")
    _same_run(fast, simulate(SheetTeam(square, 1.5), R, backend="numpy"), square.size)
    kinds |= {e.kind for e in fast.events}
    assert {"taut_change", "jump"} <= kinds


def test_backend_is_validated():
    from taut.errors import InvalidInputError
    sheet, R = team(4, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="backend"):
        simulate(SheetTeam(sheet, 1.0), R[None], backend="fortran")
    with pytest.raises(InvalidInputError, match="backend"):
        Simulator(SheetTeam(sheet, 1.0), R, backend="gpu")
