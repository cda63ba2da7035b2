"""The statics behind the physics verdicts (no MuJoCo): the least pull of taut cables on a
point load, and the rim of a rest state's basin (issue 31)."""

import numpy as np
import pytest

from taut.physics._statics import barrier, least_pull, lowest_point_load, model_pull
from taut.sheet import forward_kinematics, random_hanging_team


def _states(seed, teams):
    rng = np.random.default_rng(seed)
    for _ in range(teams):
        team, R = random_hanging_team(rng)
        yield team, R, forward_kinematics(team, R)


def test_model_pull_vanishes_exactly_at_taut_equilibria():
    # Two independent computations: taut's verdict (weights from the convex hull of the
    # lifted points) and the least sideways pull of the taut cables that carry the weight
    # with non-negative tensions (NNLS on the cables' directions). An equilibrium must
    # have no pull, a state that is not one must be pulled.
    seen = {"eq": 0, "not": 0}
    for team, R, fk in _states(5, 60):
        for e in fk.equilibria:
            pull = model_pull(team.sheet.vertices, R, team.hold_height, tuple(e.taut),
                              np.asarray(e.object), np.asarray(e.contact))
            if e.kind == "not_equilibrium":
                seen["not"] += 1
                assert pull > 1e-6, (e.taut, e.weights, pull)
            else:
                seen["eq"] += 1
                assert pull < 1e-6, (e.taut, e.weights, pull)
    assert seen["eq"] >= 60 and seen["not"] >= 20


def test_least_pull_is_invariant_to_rotating_the_plan_and_scales_with_the_load():
    rng = np.random.default_rng(3)
    for _ in range(20):
        k = int(rng.integers(4, 7))
        ang = np.sort(rng.uniform(0, 2 * np.pi, k))
        flat = np.column_stack([np.cos(ang), np.sin(ang)])
        space = np.column_stack([flat * rng.uniform(0.3, 1, (k, 1)), rng.uniform(0.2, 1, k)])
        space /= np.linalg.norm(space, axis=1)[:, None]
        fixed = rng.normal(size=2) * 0.1
        load = np.array([0.0, 0.0, 1.0])
        pull, res = least_pull(fixed, flat, space, load)
        c, s = np.cos(0.7), np.sin(0.7)
        Q = np.array([[c, -s], [s, c]])
        Q3 = np.eye(3)
        Q3[:2, :2] = Q
        p2, r2 = least_pull(Q @ fixed, flat @ Q.T, space @ Q3.T, load)
        np.testing.assert_allclose(p2, Q @ pull, atol=1e-9)
        p3, r3 = least_pull(3 * fixed, flat, space, 3 * load)
        np.testing.assert_allclose(p3, 3 * pull, atol=1e-9)
        assert abs(r3 - 3 * res) <= 1e-9


@pytest.mark.slow  # ~3.4 s of CPU: the slow target (CI runs it)
def test_lowest_point_load_is_taut_state_and_the_basin_rim_is_above_both_ends():
    # At a state's contact point the lowest point load is taut's object; the path's top
    # is at least as high as either end (so the rim bound is >= the rise to the other).
    checked = 0
    for team, R, fk in _states(11, 12):
        eqs = fk.equilibria
        V, z = team.sheet.vertices, team.hold_height
        for e in eqs:
            start = np.asarray(e.object) + [0.0, 0.0, 0.01 * z]
            p = lowest_point_load(V, R, z, np.asarray(e.contact), start)
            np.testing.assert_allclose(p, e.object, atol=1e-4 * z)
        stable = [e for e in eqs if e.kind == "stable"]
        for a in stable:
            for b in stable:
                if a is b:
                    continue
                rim = barrier(V, R, z, (np.asarray(a.object), np.asarray(a.contact)),
                              (np.asarray(b.object), np.asarray(b.contact)))
                assert rim >= max(0.0, b.object[2] - a.object[2]) - 1e-6 * z
                checked += 1
    assert checked >= 2
