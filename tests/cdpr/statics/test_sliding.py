"""Sliding of the mobile bases (friction condition) against an independent formulation with
explicit contact forces, plus the properties any friction model must have."""

import numpy as np
import pytest
from scipy.optimize import linprog

from cdpr_helpers import random_poses
from taut.cdpr import (Base, Cable, CableRobot, Platform, available_wrench_set,
                       axis_capacities, cable_state, distribute_tensions, gravity_wrench,
                       grid_points, wrench_feasible, wrench_feasible_workspace, with_friction,
                       with_stabilisers)
from taut.errors import InvalidModelError


def _contact_lp(robot, pose, tensions=None):
    """Independent check: is there an equilibrium with explicit forces at every contact
    point (each wheel or deployed stabiliser foot: normal n_c >= 0 and a friction force
    f_c in that contact's own inscribed pyramid), balancing, for every mobile base, its
    weight, the cable forces on it and the contact forces (forces in x, y, z and moments
    about the horizontal axes), with the platform in equilibrium within the tension
    limits? With ``tensions`` given they are fixed. Returns bool."""
    st = cable_state(robot, np.atleast_2d(pose))
    W, u = st.W[0], st.unit[0]
    m = robot.m
    w_req = -gravity_wrench(robot, st.R)[0]
    contacts = []                                 # (base index, world point, mu, sides)
    for k, b in enumerate(robot.bases):
        if b.mobile:
            for c in b.support_world():
                contacts.append((k, c, b.friction, b.friction_sides))
    nv = m + 3 * len(contacts)                    # t, then (n, fx, fy) per contact
    A_eq, b_eq, A_ub, b_ub = [], [], [], []
    row = np.zeros(nv)
    for i in range(W.shape[0]):                   # platform equilibrium W t = -w_e
        r = row.copy()
        r[:m] = W[i]
        A_eq.append(r)
        b_eq.append(w_req[i])
    g = robot.gravity
    for k, b in enumerate(robot.bases):
        if not b.mobile:
            continue
        com = b.to_world(b.com)
        cab = np.nonzero(robot.cable_base == k)[0]
        # forces on base k: m g + sum(-t_i u_i) + sum contact = 0   (3 equations)
        # moments about the world origin, x and y components      (2 equations)
        for axis in range(5):
            r = row.copy()
            if axis < 3:
                r[cab] = -u[cab, axis]
                rhs = -b.mass * g[axis]
            else:
                j = axis - 3
                mom = np.cross(robot.exits_world[cab], -u[cab])       # per unit tension
                r[cab] = mom[:, j]
                rhs = -np.cross(com, b.mass * g)[j]
            for ci, (kb, c, mu, sides) in enumerate(contacts):
                if kb != k:
                    continue
                base = m + 3 * ci
                F = np.eye(3)[[2, 0, 1]]           # world force of one unit of n, fx, fy
                if axis < 3:
                    r[base:base + 3] = F[:, axis]
                else:
                    r[base:base + 3] = [np.cross(c, F[q])[axis - 3] for q in range(3)]
            A_eq.append(r)
            b_eq.append(rhs)
    for ci, (kb, c, mu, sides) in enumerate(contacts):      # per-contact pyramids
        base = m + 3 * ci
        for j in range(sides):
            phi = 2 * np.pi * j / sides
            r = row.copy()
            r[base] = -mu * np.cos(np.pi / sides)
            r[base + 1], r[base + 2] = np.cos(phi), np.sin(phi)
            A_ub.append(r)
            b_ub.append(0.0)
    if tensions is None:
        tb = list(zip(robot.t_min, robot.t_max))
    else:
        tb = [(t, t) for t in tensions]
    bounds = tb + [(0, None), (None, None), (None, None)] * len(contacts)
    sol = linprog(np.zeros(nv), A_ub=np.array(A_ub), b_ub=b_ub, A_eq=np.array(A_eq),
                  b_eq=b_eq, bounds=bounds, method="highs")
    return sol.status == 0


@pytest.mark.parametrize("mu", [0.3, 0.6])
def test_friction_condition_matches_contact_force_lp(fastkit, mu):
    robot = with_friction(with_stabilisers(fastkit), mu)
    P = random_poses(robot, 30, seed=21, angle=0.1)
    exact = wrench_feasible(robot, P)
    assert 0 < exact.sum() < len(P)
    lp = np.array([_contact_lp(robot, p) for p in P])
    np.testing.assert_array_equal(exact, lp)
    # the tensions returned by the LP distribution need no other contact forces
    tr = distribute_tensions(robot, P[exact][:8], "lp_min_sum")
    assert tr.success.all() and tr.sliding and tr.tipping
    for p, t in zip(P[exact][:8], tr.tensions):
        assert _contact_lp(robot, p, np.clip(t, robot.t_min, robot.t_max))


def test_sliding_only_shrinks(fastkit):
    """(Stabilisers deployed: with them retracted tipping binds first for mu >= 0.3.)"""
    fastkit = with_stabilisers(fastkit)
    P = random_poses(fastkit, 200, seed=4, angle=0.1)
    free = wrench_feasible(fastkit, P)
    f6 = wrench_feasible(with_friction(fastkit, 0.6), P)
    f3 = wrench_feasible(with_friction(fastkit, 0.3), P)
    assert not np.any(f3 & ~f6) and not np.any(f6 & ~free)
    assert np.any(free & ~f3)                     # and here it does remove poses
    # the available wrench sets: every wrench available with friction is available
    # without; axis capacities can only drop
    Q = P[:20]
    a = available_wrench_set(fastkit, Q)
    b = available_wrench_set(with_friction(fastkit, 0.3), Q)
    g = np.random.default_rng(0)
    for _ in range(30):
        w = -a.gravity_wrench + g.normal(scale=[20, 20, 30, 3, 3, 3], size=(len(Q), 6))
        assert not np.any(b.contains(w) & ~a.contains(w))
    ca = axis_capacities(fastkit, Q)
    cb = axis_capacities(with_friction(fastkit, 0.3), Q)
    assert np.all(cb.positive <= ca.positive + 1e-9) and np.all(cb.negative <= ca.negative + 1e-9)
    # sliding=False ignores the friction coefficient
    np.testing.assert_array_equal(wrench_feasible(with_friction(fastkit, 0.3), P, sliding=False),
                                  free)


def _gantry(mu):
    """A point mass hanging from four exits of one mobile base (a gantry on wheels)."""
    exits = {f"E{i}": (sx, sy, 3.0) for i, (sx, sy) in
             enumerate([(1, 1), (-1, 1), (-1, -1), (1, -1)])}
    base = Base("gantry", exits, mobile=True, mass=80.0, com=(0, 0, 1.0),
                footprint=[[-1.5, -1.5], [1.5, -1.5], [1.5, 1.5], [-1.5, 1.5]], friction=mu)
    return CableRobot((base,), Platform({"P": (0, 0, 0)}, mass=5.0),
                      tuple(Cable(f"C{i}", "gantry", f"E{i}", "P", 1.0, 200.0)
                            for i in range(4)))


def test_frictionless_floor_resists_no_horizontal_pull(fastkit):
    robot = _gantry(0.0)
    P = np.array([[0.0, 0.0, 1.0], [0.4, -0.3, 1.5], [-0.6, 0.5, 2.0]])
    # the base carries the platform alone: the cables' horizontal pulls cancel
    assert wrench_feasible(robot, P).all()
    # ... but any horizontal push on the platform must go through the ground
    for f in ([5.0, 0, 0], [0, -5.0, 0], [1e-3, 1e-3, 0]):
        assert not wrench_feasible(robot, P, external_wrench=f).any()
    assert wrench_feasible(robot, P, external_wrench=[0, 0, -10.0]).all()
    cap = axis_capacities(robot, P)
    np.testing.assert_allclose(cap.positive[:, :2], 0.0, atol=1e-7)
    np.testing.assert_allclose(cap.negative[:, :2], 0.0, atol=1e-7)
    assert np.all(cap.negative[:, 2] > 100)       # it can still pull down hard
    # with friction a push is held; while friction binds (small mu, before tipping and
    # the tension limits) the capacity is proportional to mu: doubling mu doubles it
    c1 = axis_capacities(_gantry(0.01), P).positive[:, 0]
    c2 = axis_capacities(_gantry(0.02), P).positive[:, 0]
    assert np.all(c1 > 1.0)
    np.testing.assert_allclose(c2, 2 * c1, rtol=1e-6)
    # FASTKIT's two bases pull towards each other: nothing holds on a frictionless floor
    pts, _ = grid_points([[-2.3, 0, 0.3], [2.3, 0, 2.0]], (9, 1, 5))
    assert not wrench_feasible(with_friction(fastkit, 0.0), pts).any()


def test_workspace_reports_the_binding_condition(fastkit):
    fastkit = with_stabilisers(fastkit)
    robot = with_friction(fastkit, 0.3)
    pts, shape = grid_points(robot.desired_workspace, (15, 1, 9))
    ws = wrench_feasible_workspace(robot, pts, shape=shape)
    assert ws.feasible_sliding is not None
    assert not np.any(ws.feasible_sliding & ~ws.feasible_tipping)
    assert ws.coverage_sliding < ws.coverage_tipping
    np.testing.assert_array_equal(ws.binding == "", ws.feasible_sliding)
    np.testing.assert_array_equal(ws.binding == "limits", ~ws.feasible)
    np.testing.assert_array_equal(ws.binding == "sliding",
                                  ws.feasible_tipping & ~ws.feasible_sliding)
    assert set(ws.binding) <= {"", "limits", "tipping", "sliding"}
    plain = wrench_feasible_workspace(fastkit, pts, shape=shape)
    assert plain.feasible_sliding is None and "sliding" not in set(plain.binding)
    np.testing.assert_array_equal(plain.feasible_tipping, ws.feasible_tipping)


def test_friction_validation(fastkit):
    with pytest.raises(InvalidModelError, match="friction"):
        with_friction(fastkit, -0.1)
    with pytest.raises(InvalidModelError, match="friction_sides"):
        with_friction(fastkit, 0.3, sides=2)


def test_friction_in_the_model_file(fastkit):
    import yaml

    from taut.errors import TautError
    from taut.io.cdpr_model import cdpr_model_from_mapping, preset_path
    data = yaml.safe_load(preset_path("fastkit").read_text())
    for b in data["bases"]:
        b["friction"] = 0.3
    robot = cdpr_model_from_mapping(data)
    assert [b.friction for b in robot.bases] == [0.3, 0.3] and robot.has_sliding
    P = random_poses(fastkit, 50, seed=9)
    np.testing.assert_array_equal(wrench_feasible(robot, P),
                                  wrench_feasible(with_friction(fastkit, 0.3), P))
    data["bases"][0]["friction"] = -1.0
    with pytest.raises(TautError) as exc:
        cdpr_model_from_mapping(data)
    assert exc.value.field == "bases[0].friction"
