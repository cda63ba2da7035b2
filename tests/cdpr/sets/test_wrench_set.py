"""Available wrench set (FASTKIT eq. 24): exactness of the H-representation, tipping
containment, axis capacities against LP, analytic capacities, stabilisers, margins."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import linprog

from taut.cdpr import (available_wrench_set, axis_capacities, capacity_margin, cable_state,
                       external_wrench_box, with_stabilisers, wrench_feasible)
from taut.cdpr.statics._common import constraints  # private: the constraint rows under test

from cdpr_helpers import A, H, MASS, random_poses

G = 9.81


def lp_available(robot, pose, w, tipping):
    """Reference: is cable wrench w = W t reachable (LP feasibility)?"""
    st_ = cable_state(robot, np.atleast_2d(pose))       # the batched form constraints takes
    Amat, b = constraints(robot, st_, tipping)
    m = robot.m
    extra = Amat[0, 2 * m:]
    sol = linprog(np.zeros(m), A_ub=extra if extra.size else None,
                  b_ub=b[0, 2 * m:] if extra.size else None, A_eq=st_.W[0], b_eq=w,
                  bounds=list(zip(robot.t_min, robot.t_max)), method="highs")
    return sol.status == 0


@pytest.mark.parametrize("name,tipping", [("fastkit", True), ("fastkit", False),
                                          ("ipanema", False)])
def test_hrep_is_exact_on_random_wrenches(request, name, tipping):
    """Membership in the H-polytope equals LP feasibility, for wrenches scattered around the
    set's boundary (both inside and outside)."""
    robot = request.getfixturevalue(name)
    g = np.random.default_rng(3)
    poses = random_poses(robot, 6, seed=4)
    agree, total, inside = 0, 0, 0
    for pose in poses:
        aws = available_wrench_set(robot, pose, tipping=tipping)
        if not aws.nonempty:
            continue
        # Points near the boundary: Chebyshev-free scan along random rays from W t_mid.
        W = cable_state(robot, pose).W
        c = W @ (0.5 * (robot.t_min + robot.t_max))
        for d in g.normal(size=(40, robot.dof)):
            d /= np.linalg.norm(d)
            # exact support along d from the H-rep (ray exit), then test just in/out
            Hd = aws.H @ d                    # one pose: H (S, n)
            slack = aws.h - aws.H @ c
            s = np.min(np.where(Hd > 1e-12, slack / np.where(Hd > 1e-12, Hd, 1), np.inf))
            if not np.isfinite(s) or s <= 0:
                continue
            for f in (0.98, 1.02):
                w = c + f * s * d
                a = bool(aws.contains(w, tol=1e-7))
                b = lp_available(robot, pose, w, tipping)
                agree += a == b
                inside += a
                total += 1
    assert total > 100
    assert agree == total
    assert 0 < inside < total


def test_tipping_aws_inside_plain_aws(fastkit):
    poses = random_poses(fastkit, 300, seed=8)
    with_t = wrench_feasible(fastkit, poses, tipping=True)
    without = wrench_feasible(fastkit, poses, tipping=False)
    assert not np.any(with_t & ~without)
    assert np.any(without & ~with_t)
    # Set containment on sampled wrenches: W t for random t in the box, filtered by tipping.
    g = np.random.default_rng(9)
    for pose in poses[:5]:
        a_t = available_wrench_set(fastkit, pose, tipping=True)
        a_f = available_wrench_set(fastkit, pose, tipping=False)
        W = cable_state(fastkit, pose).W
        T = g.uniform(fastkit.t_min, fastkit.t_max, (500, fastkit.m))
        w = T @ W.T
        in_t = np.array([a_t.contains(x) for x in w])
        in_f = np.array([a_f.contains(x) for x in w])
        assert np.all(in_f)                      # every W t with t in the box
        assert not np.any(in_t & ~in_f)
    cap_t = axis_capacities(fastkit, poses[:50], tipping=True)
    cap_f = axis_capacities(fastkit, poses[:50], tipping=False)
    assert np.all(cap_t.positive <= cap_f.positive + 1e-7)
    assert np.all(cap_t.negative <= cap_f.negative + 1e-7)


@pytest.mark.parametrize("name,tipping", [("fastkit", True), ("fastkit", False),
                                          ("ipanema", False)])
def test_axis_capacities_equal_lp_optimum(request, name, tipping):
    robot = request.getfixturevalue(name)
    poses = random_poses(robot, 12, seed=12, angle=0.1)
    h = axis_capacities(robot, poses, tipping=tipping, method="hrep")
    lp = axis_capacities(robot, poses, tipping=tipping, method="lp")
    np.testing.assert_array_equal(h.feasible, lp.feasible)
    scale = robot.t_max.max()
    np.testing.assert_allclose(h.positive, lp.positive, atol=1e-6 * scale, rtol=1e-7)
    np.testing.assert_allclose(h.negative, lp.negative, atol=1e-6 * scale, rtol=1e-7)
    assert np.any(h.positive > 1.0)


@pytest.mark.parametrize("z0", [0.5, 2.0])
def test_point_mass_capacities_analytic(point_mass, z0):
    tmin, tmax = point_mass.t_min[0], point_mass.t_max[0]
    dh = H - z0
    L = np.sqrt(2 * A * A + dh * dh)
    cap = axis_capacities(point_mass, [0, 0, z0], tipping=False)
    assert cap.labels == ("fx", "fy", "fz")
    # +z: cables at t_min carry what is left of the weight; -z: all at t_max.
    np.testing.assert_allclose(cap.positive[2], MASS * G - 4 * tmin * dh / L, rtol=1e-10)
    np.testing.assert_allclose(cap.negative[2], 4 * tmax * dh / L - MASS * G, rtol=1e-10)
    # +x: the two -x cables at b, the two +x cables at a, a + b = S fixed by the weight.
    S = MASS * G * L / (2 * dh)
    b = min(tmax, S - tmin)
    fx = 2 * (b - (S - b)) * A / L
    np.testing.assert_allclose(cap.positive[0], fx, rtol=1e-10)
    np.testing.assert_allclose(cap.negative[1], fx, rtol=1e-10)
    lp = axis_capacities(point_mass, [0, 0, z0], tipping=False, method="lp")
    np.testing.assert_allclose(lp.positive, cap.positive, rtol=1e-8)


def test_stabilisers_never_reduce_capacities(fastkit):
    deployed = with_stabilisers(fastkit)
    assert all(b.stabilisers_deployed for b in deployed.bases)
    assert deployed.n_edges == fastkit.n_edges
    poses = random_poses(fastkit, 60, seed=21, angle=0.1)
    a = axis_capacities(fastkit, poses, tipping=True)
    b = axis_capacities(deployed, poses, tipping=True)
    assert np.all(b.positive >= a.positive - 1e-7)
    assert np.all(b.negative >= a.negative - 1e-7)
    assert np.any(b.positive > a.positive + 1.0) or np.any(b.negative > a.negative + 1.0)
    fa = wrench_feasible(fastkit, poses, tipping=True)
    fb = wrench_feasible(deployed, poses, tipping=True)
    assert not np.any(fa & ~fb)
    back = with_stabilisers(deployed, deployed=False)
    np.testing.assert_allclose(back.edge_weight_moment, fastkit.edge_weight_moment)


def test_capacity_margin_sign_matches_feasibility(fastkit):
    # 60 poses: 14 feasible and 46 not, with and without tipping (120: 0.6 s more CPU)
    poses = random_poses(fastkit, 60, seed=31, angle=0.05)
    D = external_wrench_box(fastkit, [3, 3, 3, 0.3, 0.3, 0.3])
    assert D.shape == (64, 6)
    for tip in (False, True):
        margin = capacity_margin(fastkit, poses, D, tipping=tip)
        feas = wrench_feasible(fastkit, poses, tipping=tip, external_wrench=D)
        sure = np.abs(margin) > 1e-6
        np.testing.assert_array_equal((margin > 0)[sure], feas[sure])
        assert feas.any() and (~feas).any()
    # The margin shrinks as the disturbance grows.
    m0 = capacity_margin(fastkit, poses, None, tipping=True)
    m1 = capacity_margin(fastkit, poses, D, tipping=True)
    ok = np.isfinite(m0)
    assert np.all(m1[ok] <= m0[ok] + 1e-9)


@settings(max_examples=25, deadline=None)
@given(x=st.floats(-2.3, 2.3), z=st.floats(0.2, 2.2), yaw=st.floats(-0.3, 0.3),
       tip=st.booleans())
def test_gravity_in_aws_iff_tensions_exist(fastkit, x, z, yaw, tip):
    from taut.cdpr import distribute_tensions
    pose = [x, 0.0, z, 0.0, 0.0, yaw]
    aws = available_wrench_set(fastkit, pose, tipping=tip)
    lp = distribute_tensions(fastkit, pose, "lp_min_sum", tipping=tip).success
    assert bool(aws.contains(-aws.gravity_wrench, tol=1e-7)) == lp
    assert bool(wrench_feasible(fastkit, pose, tipping=tip)) == lp


@settings(max_examples=15, deadline=None)
@given(half=st.floats(0.5, 3.0), height=st.floats(1.0, 4.0), z=st.floats(0.05, 0.9),
       x=st.floats(-0.9, 0.9), tmin=st.floats(0.0, 5.0), span=st.floats(20.0, 200.0),
       seed=st.integers(0, 10_000))
def test_random_point_mass_robots(half, height, z, x, tmin, span, seed):
    """Random 5-cable point-mass robots (r = 2 redundant cables, unequal limits): exact
    feasibility and capacities agree with the LP; closed form feasible => LP feasible."""
    from taut.cdpr import Base, Cable, CableRobot, Platform, distribute_tensions
    g = np.random.default_rng(seed)
    ang = np.sort(g.uniform(0, 2 * np.pi, 5))
    exits = {f"A{i}": (half * np.cos(a), half * np.sin(a), height * g.uniform(0.8, 1.0))
             for i, a in enumerate(ang)}
    lims = [(tmin * g.uniform(0.5, 1.0), tmin + span * g.uniform(0.5, 1.0)) for _ in ang]
    robot = CableRobot((Base("frame", exits),), Platform({"P": (0, 0, 0)}, mass=3.0),
                       tuple(Cable(f"C{i}", "frame", f"A{i}", "P", *lims[i])
                             for i in range(5)))
    lo, hi = robot.bounds
    pose = [lo[0] + 0.5 * (x + 1) * (hi[0] - lo[0]), 0.5 * (lo[1] + hi[1]), z * hi[2]]
    lp = distribute_tensions(robot, pose, "lp_min_sum").success
    assert bool(wrench_feasible(robot, pose, tipping=False)) == lp
    assert distribute_tensions(robot, pose, "qp_min_norm").success == lp
    if distribute_tensions(robot, pose, "closed_form").success:
        assert lp
    a = axis_capacities(robot, pose, tipping=False)
    b = axis_capacities(robot, pose, tipping=False, method="lp")
    np.testing.assert_array_equal(a.feasible, b.feasible)
    np.testing.assert_allclose(a.positive, b.positive, atol=1e-6 * span, rtol=1e-7)
    np.testing.assert_allclose(a.negative, b.negative, atol=1e-6 * span, rtol=1e-7)


def test_three_redundant_cables_generic():
    """r = 3 (six cables on a point mass): the general Farkas-certificate path."""
    from taut.cdpr import Base, Cable, CableRobot, Platform, distribute_tensions
    g = np.random.default_rng(5)
    ang = np.sort(g.uniform(0, 2 * np.pi, 6))
    exits = {f"A{i}": (2 * np.cos(a), 2 * np.sin(a), g.uniform(2.5, 3.0))
             for i, a in enumerate(ang)}
    robot = CableRobot((Base("frame", exits),), Platform({"P": (0, 0, 0)}, mass=5.0),
                       tuple(Cable(f"C{i}", "frame", f"A{i}", "P", 1.0, 30.0 + 3 * i)
                             for i in range(6)))
    lo, hi = robot.bounds
    P = np.column_stack([g.uniform(lo, hi, (150, 3))])
    lp = distribute_tensions(robot, P, "lp_min_sum").success
    assert 0 < lp.sum() < len(P)
    np.testing.assert_array_equal(wrench_feasible(robot, P, tipping=False), lp)
    np.testing.assert_array_equal(distribute_tensions(robot, P, "qp_min_norm").success, lp)
    a = axis_capacities(robot, P[:10], tipping=False)
    b = axis_capacities(robot, P[:10], tipping=False, method="lp")
    np.testing.assert_allclose(a.positive, b.positive, atol=1e-6)
    np.testing.assert_allclose(a.negative, b.negative, atol=1e-6)


def ring_robot(m, point_mass=False):
    """A fixed frame with ``m`` cables from a ring of exits to a ring of anchors (6-DoF), or
    to one point (3-DoF)."""
    from taut.cdpr import Base, Cable, CableRobot, Platform
    ang = 2 * np.pi * np.arange(m) / m
    exits = {f"A{i}": (3 * np.cos(a), 3 * np.sin(a), 3.0 if i % 2 else 0.5)
             for i, a in enumerate(ang)}
    anchors = {f"B{i}": (0.0, 0.0, 0.0) if point_mass else
               (0.4 * np.cos(a), 0.4 * np.sin(a), 0.2 if i % 2 else -0.2)
               for i, a in enumerate(ang)}
    return CableRobot((Base("frame", exits),), Platform(anchors, mass=10.0),
                      tuple(Cable(f"C{i}", "frame", f"A{i}", f"B{i}", 5.0, 500.0)
                            for i in range(m)))


@pytest.mark.parametrize("robot, tipping", [("fastkit", True), ("fastkit", False),
                                            ("ipanema", False), ("six point", False)])
def test_predicted_candidates_are_the_enumerated_rows(request, robot, tipping):
    """The closed-form count of the budget is the number of rows the AWS builds."""
    from taut.cdpr.sets._budget import wrench_work
    robot = ring_robot(6, point_mass=True) if robot == "six point" else \
        request.getfixturevalue(robot)
    aws = available_wrench_set(robot, [0, 0, 1.0], tipping=tipping)
    assert aws.H.shape[0] == wrench_work(robot, tipping, robot.has_sliding)[0]


def test_wrench_set_past_its_budget_is_refused_before_any_work():
    """13 cables on a 6-DoF platform (1.56 million candidate facets) and 11 on a point
    (3-DoF, r = 8) are refused, naming the cable count and the numbers; 12 cables (the
    tests' twelve-cable model, 0.35 million) and every preset are accepted."""
    from taut._validate import MAX_SET_NUMBERS
    from taut.cdpr.sets._budget import wrench_work
    from taut.errors import InvalidInputError
    from taut.io.cdpr_model import PRESETS, load_cdpr_model
    from cdpr_helpers import twelve_cable_robot
    for robot, m in [(ring_robot(13), 13), (ring_robot(11, point_mass=True), 11)]:
        for call in (lambda: available_wrench_set(robot, [0, 0, 1.5], tipping=False),
                     lambda: wrench_feasible(robot, [[0, 0, 1.5]] * 3),
                     lambda: capacity_margin(robot, [0, 0, 1.5]),
                     lambda: axis_capacities(robot, [0, 0, 1.5])):
            with pytest.raises(InvalidInputError) as e:
                call()
            assert e.value.field == "cables"
            assert f"{m} cables give " in e.value.problem
            assert f"at most {MAX_SET_NUMBERS:,} numbers" in e.value.problem
    assert wrench_work(twelve_cable_robot(), True, True)[1] <= MAX_SET_NUMBERS
    for name in PRESETS:
        robot = load_cdpr_model(name)
        assert wrench_work(robot, True, True)[1] <= MAX_SET_NUMBERS


def test_capacity_margin_in_blocks_equals_one_set(fastkit, monkeypatch):
    """capacity_margin enumerates the facets of a block of poses at a time; with blocks of
    two poses it returns what the whole batch gives."""
    import taut.cdpr.sets._budget as budget
    P = random_poses(fastkit, 7, seed=3)
    whole = capacity_margin(fastkit, P, tipping=True)
    work = budget.wrench_work(fastkit, True, fastkit.has_sliding)
    assert budget.block_size(work, 256) == 256
    monkeypatch.setattr(budget, "MAX_SET_NUMBERS", 2 * work[1])
    assert budget.block_size(work, 256) == 2
    np.testing.assert_array_equal(capacity_margin(fastkit, P, tipping=True), whole)
