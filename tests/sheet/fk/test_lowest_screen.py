"""The screen "can the direct minimisation supply a stable state?" (fk._lowest.may_find_stable)
for one formation and for a batch (``may_find_stable_batch``, what
``BatchFKResult.success`` runs) make the same decision."""

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from taut.sheet import SheetTeam, forward_kinematics_batch, random_team
from taut.sheet._tol import DIRECT_RTOL
from taut.sheet.fk import _lowest
from taut.sheet.fk._lowest import may_find_stable, may_find_stable_batch


def _formations(V: np.ndarray, rng: np.random.Generator, B: int) -> np.ndarray:
    """``B`` formations of the sheet ``V``: exact similar copies, copies moved by noise
    around the screen's threshold (``DIRECT_RTOL`` of the size, 1e-3 here: 1e-6..1e-1),
    and unrelated random ones."""
    size = float(np.ptp(V, axis=0).max())
    out = []
    for b in range(B):
        angle, scale = rng.uniform(0, 2 * np.pi), rng.uniform(0.3, 1.2)
        Q = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        copy = scale * (V - V.mean(axis=0)) @ Q.T + rng.normal(size=2) * size
        kind = b % 3
        if kind == 0:
            out.append(copy)
        elif kind == 1:
            out.append(copy + rng.normal(size=V.shape) * size * 10 ** rng.uniform(-6, -1))
        else:
            out.append(rng.normal(size=V.shape) * size)
    return np.array(out)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 30), B=st.integers(1, 9))
@example(seed=0, n=9, B=1)          # one formation: numpy would sum pairwise along N
@example(seed=1, n=12, B=2)
def test_batch_screen_agrees_with_scalar(seed, n, B):
    rng = np.random.default_rng(seed)
    sheet, _ = random_team(n, rng)
    V, size = sheet.vertices, sheet.size
    F = _formations(V, rng, B)
    batch = may_find_stable_batch(V, F, size)
    dist = _lowest._copy_distances(V, F)
    assert batch.shape == (B,) and batch.dtype == bool
    for b in range(B):
        d = _lowest._copy_distance(V, F[b])
        if n <= _lowest._PY_MAX_N:
            assert d == dist[b]                   # the same operations, bit for bit
        else:
            assert abs(d - dist[b]) <= 1e-12 * size
        if abs(d - DIRECT_RTOL * size) > 1e-12 * size:
            assert may_find_stable(V, F[b], size) == batch[b]
        if b % 3 == 0:                            # an exact similar copy
            assert d <= 1e-9 * size and batch[b]


def test_batch_screen_threshold():
    """Either side of the threshold: a copy with one robot moved by 0.9 and 1.5 x
    ``DIRECT_RTOL`` of the size (the fit follows the robot a little: its distance is less
    than the move), and an unrelated formation."""
    rng = np.random.default_rng(7)
    sheet, R = random_team(5, rng)
    V, size = sheet.vertices, sheet.size
    copy = 0.8 * V
    F = np.array([copy, copy, copy, R])
    F[1, 2, 0] += 0.9 * DIRECT_RTOL * size
    F[2, 2, 0] += 1.5 * DIRECT_RTOL * size
    got = may_find_stable_batch(V, F, size).tolist()
    assert got == [may_find_stable(V, f, size) for f in F]
    assert got[:2] == [True, True] and got[3] is False


def test_batch_success_without_stable_states_matches_single_results():
    """``BatchFKResult.success`` on formations without a stable state (the batched screen)
    is each formation's own ``success``, next to a similar copy of the sheet and away."""
    rng = np.random.default_rng(3)
    for _ in range(100):
        sheet, R = random_team(3, rng)
        team = SheetTeam(sheet, 2.0 * sheet.size)
        if not forward_kinematics_batch(team, R[None]).success[0]:
            break
    noise = rng.normal(size=(12, 3, 2)) * 0.02 * sheet.size
    copy = 0.9 * sheet.vertices                    # next to a similar copy: the descent runs
    F = np.concatenate([R[None] + noise, [copy, copy + 1e-5 * sheet.size]])
    batch = forward_kinematics_batch(team, F)
    assert batch.feasible.all() and not batch.success[:12].any()
    single = [forward_kinematics_batch(team, f[None]).result(0).success for f in F]
    assert batch.success.tolist() == single


#: Suite-2024 scenario 39's narrow formation (planner, issue 23): six robots all taut at
#: one point by construction (IK), a measure-zero set where rounding decides whether the
#: enumeration's five-cable solution counts the sixth cable taut; on an AMD EPYC host the
#: enumeration lost the state and ``.stable`` (screened) said "none" while
#: ``.equilibria`` (with the descent) held it.
HEXAGON = np.array([[0.6621373214178711, 0.0441876689983892],
                    [0.2928010168223125, 0.595521575640853],
                    [-0.36933630459555844, 0.551333906642464],
                    [-0.6621373214178711, -0.04418766899838906],
                    [-0.29280101682231247, -0.595521575640853],
                    [0.3693363045955589, -0.5513339066424636]])
NARROW = np.array([[0.5061532139022916, 0.033778069947203816],
                   [0.3268049787709241, 0.38798258197034285],
                   [-0.3268048077479725, 0.3879825819703392],
                   [-0.5061529920437874, -0.033778085107707884],
                   [-0.32680480774796977, -0.38798258197034224],
                   [0.32680497877092735, -0.3879825819703409]])


def test_more_than_five_robots_always_get_the_descent():
    """Every formation of a team of more than GENERIC_TAUT_MAX robots is screened in
    (single and batch), and the narrow hexagon's answer does not depend on which
    property is read first."""
    from taut.sheet import Sheet, forward_kinematics
    team = SheetTeam(Sheet(HEXAGON), 0.4678392926499957)
    assert may_find_stable(HEXAGON, NARROW, team.sheet.size)
    assert may_find_stable_batch(HEXAGON, np.stack([NARROW, 2 * NARROW]),
                                 team.sheet.size).tolist() == [True, True]
    first_stable = forward_kinematics(team, NARROW).stable
    first_all = [e for e in forward_kinematics(team, NARROW).equilibria if e.stable]
    assert len(first_stable) == len(first_all) == 1
    assert first_stable[0].taut == first_all[0].taut == (0, 1, 2, 3, 4, 5)
    np.testing.assert_allclose(first_stable[0].object, [0, 0, 0.04], atol=1e-6)
    assert forward_kinematics_batch(team, NARROW[None]).success.tolist() == [True]


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 9), shrink=st.floats(0.6, 0.99))
def test_what_is_read_first_does_not_change_the_answer(seed, n, shrink):
    """``success`` and ``stable`` read first on a fresh result agree with the full list
    of states (``equilibria``, which always runs the descent when no state is stable), on
    random teams and on formations near a similar copy of the sheet."""
    from taut.sheet import forward_kinematics
    rng = np.random.default_rng(seed)
    sheet, R = random_team(n, rng)
    team = SheetTeam(sheet, 1.5 * sheet.size)
    for F in (R, shrink * sheet.vertices + 1e-4 * sheet.size * rng.normal(size=(n, 2))):
        success = forward_kinematics(team, F).success
        stable = forward_kinematics(team, F).stable
        full = [e for e in forward_kinematics(team, F).equilibria if e.stable]
        assert success == bool(full) == bool(stable)
        assert sorted(e.taut for e in stable) == sorted(e.taut for e in full)
