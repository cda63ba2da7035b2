"""First-order kinematics and available twist set of mobile CDPRs (FASTKIT §3, eqs. 1-16)."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial.transform import Rotation

from taut.cdpr import Base, Cable, CableRobot, Payload, Platform, cable_state
from taut.cdpr import (MotionLimits, available_twist_set, fastkit_motion_limits,
                             first_order_model, parallel_jacobian, resolve_mode, support,
                             twist_capacities, zonotope_hrep)
from taut.errors import InvalidInputError, TautError

POSES = np.array([[0.3, 0.05, 1.0, 0.05, -0.03, 0.1],
                  [-1.2, -0.1, 0.6, 0.0, 0.08, -0.05],
                  [1.5, 0.1, 1.4, -0.06, 0.0, 0.02]])


def _moved(pose, t, h):
    """Pose after moving along twist t = [v; w] for time h (world-frame rotation)."""
    R0 = Rotation.from_euler("ZYX", pose[[5, 4, 3]])
    R1 = Rotation.from_rotvec(t[3:] * h) * R0
    ypr = R1.as_euler("ZYX")
    return np.r_[pose[:3] + t[:3] * h, ypr[2], ypr[1], ypr[0]]


def _move_base(robot, k, dq, h):
    """Move base k along RPP rates dq = (theta_dot, rho1_dot, rho2_dot) for time h."""
    b = robot.bases[k]
    th = b.pose[2]
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    d = R @ dq[1:] * h
    nb = replace(b, exit_points=dict(b.exit_points),
                 pose=(b.pose[0] + d[0], b.pose[1] + d[1], th + dq[0] * h))
    bases = list(robot.bases)
    bases[k] = nb
    return replace(robot, bases=tuple(bases), bounds=None)


def three_base_robot():
    """Point-mass platform held by 6 cables from 3 mobile bases at 120 degrees."""
    bases, cables = [], []
    for k in range(3):
        a = 2 * np.pi * k / 3
        bases.append(Base(f"b{k}", {"L": (0.3, 0.4, 2.0), "R": (0.3, -0.4, 2.2)},
                          pose=(-2.5 * np.cos(a), -2.5 * np.sin(a), a), mobile=True, mass=40.0,
                          com=(0.0, 0.0, 0.5),
                          footprint=[(-0.4, -0.5), (0.4, -0.5), (0.4, 0.5), (-0.4, 0.5)]))
        cables += [Cable(f"c{k}L", f"b{k}", "L", "P", 2.0, 80.0),
                   Cable(f"c{k}R", f"b{k}", "R", "P", 2.0, 80.0)]
    return CableRobot(tuple(bases), Platform({"P": (0, 0, 0)}, mass=3.0), tuple(cables),
                      Payload(0.0), name="tri")


def test_parallel_jacobian_matches_finite_differences(fastkit):
    g = np.random.default_rng(3)
    h = 1e-6
    for pose in POSES:
        A = parallel_jacobian(fastkit, pose)       # one pose: (m, n)
        for _ in range(3):
            t = g.normal(size=6)
            fd = (cable_state(fastkit, _moved(pose, t, h)).lengths
                  - cable_state(fastkit, _moved(pose, t, -h)).lengths) / (2 * h)
            np.testing.assert_allclose(A @ t, fd, atol=1e-7)


@pytest.mark.parametrize("robot_name", ["fastkit", "tri"])
def test_base_jacobian_matches_finite_differences(robot_name, fastkit):
    robot = fastkit if robot_name == "fastkit" else three_base_robot()
    poses = POSES[:, :3] * [0.3, 1, 1] if robot_name == "tri" else POSES
    names = tuple(b.name for b in robot.bases)
    g = np.random.default_rng(4)
    h = 1e-6
    for pose in poses:
        fom = first_order_model(robot, pose, "task", names)
        assert fom.B.shape == (robot.m, 3 * len(names) + robot.m)   # one pose
        for k in range(len(names)):
            dq = g.normal(size=3)
            fd = (cable_state(_move_base(robot, k, dq, h), pose).lengths
                  - cable_state(_move_base(robot, k, dq, -h), pose).lengths) / (2 * h)
            # platform still (t = 0): 0 = B_b q_b + l_dot  =>  l_dot = -B_b q_b  (eq. 8)
            np.testing.assert_allclose(-fom.B_b[:, 3 * k:3 * k + 3] @ dq, fd, atol=1e-7)
            # only that base's cables change length
            assert np.allclose(fd[robot.cable_base != k], 0.0, atol=1e-7)


def test_full_model_combined_motion(fastkit):
    """Platform and both bases moving together: A t = B q_dot (eq. 9) predicts l_dot."""
    pose, h = POSES[0], 1e-6
    fom = first_order_model(fastkit, pose, "task", ("active", "passive"))
    t = np.array([0.2, -0.1, 0.3, 0.05, 0.02, -0.04])
    qa, qp = np.array([0.1, 0.2, -0.1]), np.array([-0.05, 0.1, 0.15])

    def lengths(s):
        r = _move_base(_move_base(fastkit, 0, qa, s), 1, qp, s)
        return cable_state(r, _moved(pose, t, s)).lengths

    ldot = (lengths(h) - lengths(-h)) / (2 * h)
    q = np.concatenate([qa, qp, ldot])
    np.testing.assert_allclose(fom.A @ t, fom.B @ q, atol=1e-7)


def test_zonotope_hrep_is_exact():
    g = np.random.default_rng(0)
    G = g.normal(size=(1, 4, 7))
    c = g.normal(size=(1, 4))
    H, h = zonotope_hrep(c, G)
    s = g.uniform(-1, 1, size=(500, 7))
    x = c[0] + s @ G[0].T
    assert np.all(x @ H[0].T <= h[0] + 1e-9)
    # the point maximising d.x (generators signed by d) is on the boundary; 1 % beyond
    # it (away from the centre) is outside
    d = g.normal(size=4)
    xs = c[0] + G[0] @ np.sign(d @ G[0])
    assert np.max(xs @ H[0].T - h[0]) == pytest.approx(0.0, abs=1e-9)
    assert np.max((c[0] + 1.01 * (xs - c[0])) @ H[0].T - h[0]) > 0
    # support function from the H-rep equals the generator formula for random directions
    for _ in range(5):
        d = g.normal(size=4)
        lp = linprog(-d, A_ub=H[0][np.isfinite(h[0])], b_ub=h[0][np.isfinite(h[0])],
                     bounds=[(None, None)] * 4, method="highs")
        assert -lp.fun == pytest.approx(d @ c[0] + np.abs(d @ G[0]).sum(), rel=1e-7)


@pytest.mark.parametrize("moving", [None, ()])
def test_axis_capacities_equal_lp_optimum(fastkit, moving):
    a = twist_capacities(fastkit, POSES, moving=moving, method="hrep")
    b = twist_capacities(fastkit, POSES, moving=moving, method="lp")
    np.testing.assert_allclose(a.positive, b.positive, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(a.negative, b.negative, rtol=1e-7, atol=1e-9)
    assert np.all(a.positive > 0) and np.all(a.feasible)


def test_support_function_two_formulations(fastkit):
    """max d.t over the H-rep equals max d.t over joint rates (A t = B q, q in box)."""
    g = np.random.default_rng(7)
    lim = fastkit_motion_limits()
    for pose in POSES[:2]:
        ats = available_twist_set(fastkit, pose, lim)
        A, B = ats.model.A, ats.model.B
        lo = np.r_[lim.base_min, np.full(8, -2.0)]
        hi = np.r_[lim.base_max, np.full(8, 2.0)]
        for _ in range(4):
            d = g.normal(size=6)
            c = np.r_[-d, np.zeros(B.shape[1])]
            sol = linprog(c, A_eq=np.hstack([A, -B]), b_eq=np.zeros(8),
                          bounds=[(None, None)] * 6 + list(zip(lo, hi)), method="highs")
            assert support(ats, d) == pytest.approx(-sol.fun, rel=1e-7)
            # the optimal twist is in the set; pushed 1 % further it is not
            t = sol.x[:6]
            assert ats.contains(t, tol=1e-7)
            assert not ats.contains(1.01 * t)


def test_moving_bases_capacities_at_least_fixed(fastkit):
    """The paper's Fig. 13 claim: bases moving never reduce the twist capacities, and the
    active base adds capacity along x here."""
    mv = twist_capacities(fastkit, POSES)
    fx = twist_capacities(fastkit, POSES, moving=())
    assert np.all(mv.positive >= fx.positive - 1e-9)
    assert np.all(mv.negative >= fx.negative - 1e-9)
    assert np.any(mv.positive[:, 0] > fx.positive[:, 0] + 1e-3)


def test_membership_from_joint_rates(fastkit):
    """Twists produced by random in-limit joint rates are members; the fixed-base set is a
    subset of the moving-base set."""
    g = np.random.default_rng(11)
    pose = POSES[1]
    mv = available_twist_set(fastkit, pose)
    fx = available_twist_set(fastkit, pose, moving=())
    A = mv.model.A
    Bb = mv.model.B[:, :3]
    inside = 0
    for _ in range(200):
        t = g.normal(size=6) * [1, 1, 1, 3, 3, 3]
        qb = g.uniform(-0.2, 0.2, 3)
        ldot = A @ t - Bb @ qb
        ok = np.all(np.abs(ldot) <= 2.0)
        assert mv.contains(t, tol=1e-9) or not ok
        if ok:
            inside += 1
        if fx.contains(t):
            assert mv.contains(t)
        # with bases fixed, membership is exactly |A t| <= 2
        assert fx.contains(t, tol=1e-9) == bool(np.all(np.abs(A @ t) <= 2.0 + 1e-9))
    assert inside > 20


def test_navigation_mode(fastkit):
    pose = np.array([0.3, 0.0, 1.0])
    cap = twist_capacities(fastkit, pose, mode="navigation")
    lp = twist_capacities(fastkit, pose, mode="navigation", method="lp")
    np.testing.assert_allclose(cap.positive, lp.positive, atol=1e-9)
    # active base at x = -3: pure vx / vy limited by the base speed; pure wz about P needs
    # the base origin to move at |r| wz, |r| = 3.3 m
    assert cap.positive[0] == pytest.approx(0.2)
    assert cap.positive[1] == pytest.approx(0.2)
    assert cap.positive[5] == pytest.approx(0.2 / 3.3)
    assert np.allclose(cap.positive[2:5], 0.0)
    ats = available_twist_set(fastkit, pose, mode="navigation")
    assert ats.contains([0.1, 0.1, 0, 0, 0, 0])
    assert not ats.contains([0.1, 0.0, 0.05, 0, 0, 0])      # cannot lift in navigation


def test_point_mass_three_dof():
    robot = three_base_robot()
    cap = twist_capacities(robot, [0.0, 0.0, 1.0], moving=("b0", "b1"))
    fix = twist_capacities(robot, [0.0, 0.0, 1.0], moving=())
    assert cap.positive.shape == (3,)
    np.testing.assert_allclose(cap.positive, twist_capacities(
        robot, [0.0, 0.0, 1.0], moving=("b0", "b1"), method="lp").positive, rtol=1e-7)
    assert np.all(cap.positive >= fix.positive - 1e-9)
    # navigation on a point mass: the driver's twist map has rank 2 (no vz); the set is
    # exact, so the LP over joint rates agrees
    nav = twist_capacities(robot, [0.2, 0.1, 1.0], mode="navigation", moving=("b1",))
    nav_lp = twist_capacities(robot, [0.2, 0.1, 1.0], mode="navigation", moving=("b1",),
                              method="lp")
    np.testing.assert_allclose(nav.positive, nav_lp.positive, atol=1e-9)
    np.testing.assert_allclose(nav.negative, nav_lp.negative, atol=1e-9)
    assert nav.positive[2] == 0.0 and nav.positive[0] > 0.2 - 1e-9


def test_limits_defaults_and_validation():
    lim = fastkit_motion_limits()
    assert np.allclose(lim.base_max, 0.2) and np.allclose(lim.cable_max, 2.0)
    with pytest.raises(InvalidInputError, match="exceeds"):
        MotionLimits(cable_min=1.0, cable_max=-1.0)
    with pytest.raises(InvalidInputError, match="exceeds"):
        MotionLimits(base_min=(0.1, 0, 0), base_max=(0.0, 0.2, 0.2))
    with pytest.raises(InvalidInputError, match="NaN"):
        MotionLimits(cable_max=float("nan"))
    with pytest.raises(InvalidInputError):
        MotionLimits(base_min=(0, 0), base_max=(1, 1, 1))
    with pytest.raises(InvalidInputError, match="span"):
        available_twist_set(three_base_robot(), [0, 0, 1.0], MotionLimits(
            cable_min=[-1, -1, -1, -1, -1, 0.5], cable_max=[1, 1, 1, 1, 1, 0.5]), moving=())
    with pytest.raises(InvalidInputError, match="entries"):
        available_twist_set(three_base_robot(), [0, 0, 1.0],
                            MotionLimits(cable_min=[-1] * 4, cable_max=[1] * 4))


def test_mode_errors(fastkit, point_mass):
    with pytest.raises(InvalidInputError, match="no base named 'ghost'"):
        resolve_mode(fastkit, "task", ("ghost",))
    with pytest.raises(InvalidInputError, match="unknown mode"):
        resolve_mode(fastkit, "flying")
    with pytest.raises(InvalidInputError, match="exactly one"):
        resolve_mode(fastkit, "navigation", ("active", "passive"))
    with pytest.raises(InvalidInputError, match="fixed frame"):
        resolve_mode(point_mass, "task", ("frame",))
    with pytest.raises(InvalidInputError):
        twist_capacities(fastkit, [0.0, 0.0, float("nan")])
    assert resolve_mode(fastkit).names == ("active",)
    assert resolve_mode(fastkit, "task", ()).moving == ()
    with pytest.raises(TautError):
        available_twist_set(fastkit, [0.0, 0.0, 1.0]).contains([1.0, 2.0])


@pytest.mark.parametrize("moving", [None, (), pytest.param(("active", "passive"),
                                                            marks=pytest.mark.slow)])
def test_structured_facets_equal_generic(fastkit, moving):
    """The task-mode fast path (base columns + cable identity columns) yields exactly the
    facets of the generic zonotope enumeration."""
    from taut.cdpr import joint_bounds
    ats = available_twist_set(fastkit, POSES, moving=moving)
    fom = ats.model
    lo, hi = joint_bounds(fastkit, fastkit_motion_limits(), fom.mode)
    Hz, hz = zonotope_hrep(np.einsum("bmq,q->bm", fom.B, 0.5 * (lo + hi)),
                           fom.B * (0.5 * (hi - lo)))
    for b in range(len(POSES)):
        Ht = np.einsum("sm,mn->sn", Hz[b], fom.A[b])
        nrm = np.linalg.norm(Ht, axis=1)
        fin = np.isfinite(hz[b]) & (nrm > 1e-12)
        ref = np.column_stack([Ht[fin], hz[b][fin]]) / nrm[fin, None]
        got = np.column_stack([ats.H[b], ats.h[b]])[np.isfinite(ats.h[b])]
        dist = np.abs(ref[:, None, :] - got[None, :, :]).max(axis=2)
        assert dist.min(axis=1).max() < 1e-7          # every generic facet is found
        assert dist.min(axis=0).max() < 1e-7          # and nothing else


@pytest.mark.parametrize("moving, frozen", [(None, False), ((), False),
                                            (("active", "passive"), False), (None, True)])
def test_predicted_twist_facets_are_the_enumerated_rows(fastkit, moving, frozen):
    """The closed-form count of the budget is the number of rows the task-mode set
    builds, on the structured path and (one cable frozen) the generic one."""
    from taut.cdpr.sets._budget import twist_work
    lim = fastkit_motion_limits()
    if frozen:
        lo = np.full(fastkit.m, -2.0)
        lo[0] = 0.0
        lim = replace(lim, cable_min=lo, cable_max=np.where(lo == 0.0, 0.0, 2.0))
    ats = available_twist_set(fastkit, POSES[0], lim, moving=moving)
    nb = 3 * len(ats.mode.moving)
    assert ats.H.shape[0] == twist_work(fastkit.m, nb, fastkit.m - int(frozen))[0]


def test_twist_set_past_its_budget_is_refused_before_any_work(fastkit):
    """FASTKIT's active base copied 5 times around the platform (20 cables) with two
    moving bases: 1.3 million candidate facets, refused naming the cables and the moving
    base joints; fixed bases, one moving base, and every preset with both moving pass."""
    from taut._validate import MAX_SET_NUMBERS
    from taut.cdpr.sets._budget import twist_work
    from taut.io.cdpr_model import PRESETS, load_cdpr_model
    act = fastkit.bases[0]
    cables = [c for c in fastkit.cables if c.base == act.name]
    bases, cab = [], []
    for k in range(5):
        phi = 2 * np.pi * k / 5
        name = f"b{k}"
        bases.append(replace(act, name=name, pose=(-3 * np.cos(phi), -3 * np.sin(phi), phi)))
        cab += [replace(c, name=f"{c.name}{k}", base=name) for c in cables]
    att = {f"{c.attachment}": fastkit.platform.attachment_points[c.attachment]
           for c in cables}
    robot = CableRobot(tuple(bases), replace(fastkit.platform, attachment_points=att),
                       tuple(cab))
    with pytest.raises(InvalidInputError) as e:
        available_twist_set(robot, [0, 0, 1.5], moving=("b0", "b1"))
    assert e.value.field == "cables"
    assert "20 cables and 6 moving base joints give 1,315,600 candidate facets" \
        in e.value.problem
    with pytest.raises(InvalidInputError):
        twist_capacities(robot, [0, 0, 1.5], moving=("b0", "b1"))
    assert available_twist_set(robot, [0, 0, 1.5], moving=()).H.shape[0] == 40
    assert twist_work(20, 3, 20)[1] <= MAX_SET_NUMBERS
    for name in PRESETS:
        assert twist_work(load_cdpr_model(name).m, 6, 8)[1] <= MAX_SET_NUMBERS
