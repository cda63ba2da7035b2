"""Control simulation of the CDPR: rest, energy, tipping monitor, tracking, bad input.

Short runs use the numpy backend (no compilation); the paper's claim and the backend
cross-check are marked slow.
"""

import numpy as np
import pytest

from taut.cdpr import (BaseMotion, Controller, DynamicsModel, ModelErrors, Sensing,
                       TorqueController, VelocityController, distribute_tensions, monte_carlo,
                       pick_and_place, reference_from_samples, simulate, tipping_moments,
                       with_stabilisers)
from taut.cdpr.control.model_errors import stack_perturbations
from taut.cdpr.control.plant import Plant, initial_state
from taut.errors import InfeasiblePoseError, InvalidInputError, InvalidModelError

HOLD = np.array([0.3, 0.0, 1.0, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def fk_stab():
    from taut.io.cdpr_model import load_cdpr_model
    return with_stabilisers(load_cdpr_model("fastkit"))


def _hold(robot, pose, seconds=0.5):
    t = np.linspace(0.0, seconds, 11)
    return reference_from_samples(robot, t, np.tile(pose, (11, 1)))


@pytest.mark.parametrize("controller", [VelocityController(), TorqueController()],
                         ids=["velocity", "torque"])
def test_rest_holds_pose_and_tensions_match_the_distribution(fk_stab, controller):
    # exact encoders: one count (0.38 um of cable) is 2.5 mN of tension on FASTKIT's cables
    run = simulate(fk_stab, _hold(fk_stab, HOLD), controller, backend="numpy",
                   sensing=Sensing(encoder_counts=0))
    assert run.success, run.message
    assert np.abs(run.poses - HOLD).max() < 1e-6
    ref = distribute_tensions(fk_stab, HOLD, "closed_form", tipping=False).tensions
    assert np.abs(run.tensions - ref).max() < 1e-4          # N, of ~30 N
    # Tipping margins from the simulation = -tipping_moments at the same static state.
    tm = tipping_moments(fk_stab, run.poses[-1], run.tensions[-1]).moments
    assert np.allclose(run.tipping_margin[-1], -tm, atol=1e-9, rtol=1e-12)


def test_tipping_monitor_with_errors_matches_tipping_moments_at_rest(fk_stab):
    run = simulate(fk_stab, _hold(fk_stab, HOLD, 0.3), TorqueController(), backend="numpy",
                   model_errors=ModelErrors(exit_offset=0.0, mass_scale=1.1))
    k = len(run.times) - 1
    tm = tipping_moments(fk_stab, run.poses[k], run.tensions[k]).moments
    assert np.allclose(run.tipping_margin[k], -tm, atol=1e-6)


class _HoldTorque(Controller):
    """Controllers off: every motor keeps the constant torque it had at rest."""

    name = "hold"

    def __init__(self, tau):
        self.tau = tau

    def command(self, ctx, k, meas):
        return np.broadcast_to(self.tau, meas.L0.shape)


def _energy_run(robot, dyn, seconds, h):
    """Controllers off: from rest at equilibrium, kick the platform and let it swing with
    every motor holding its constant rest torque (a conservative load)."""
    from taut.cdpr import cable_state
    pl = Plant(robot, dyn, stack_perturbations(robot, None))
    ex = robot.exits_world.T.copy()
    t = distribute_tensions(robot, HOLD, "closed_form", tipping=False).tensions
    L = cable_state(robot, HOLD).lengths
    L0 = dyn.cable_stiffness * L / (dyn.cable_stiffness + t)
    s = initial_state(pl, ex, L0[None], HOLD)
    s.vc += [0.04, 0.03, -0.05]
    s.wb += [0.1, -0.08, 0.05]
    tau = (dyn.length_per_rad * t / dyn.efficiency)[None]
    L0s = s.L0.copy()
    zero = np.zeros_like(ex)
    E, v = [], []
    for k in range(int(round(seconds / h))):
        if k % 20 == 0:
            E.append(pl.energy(s, ex, tau, L0s)[0])
            v.append(np.abs(s.speed).max())
        pl.step(s, h, ex, zero, tau)
    return np.array(E), np.array(v)


def test_energy_is_conserved_without_losses(fastkit):
    dyn = DynamicsModel().without_losses()
    E, v = _energy_run(fastkit, dyn, 2.0, 1e-3)
    assert v.max() > 0.5                                     # the rotors do turn, rad/s
    assert np.abs(E - E[0]).max() / abs(E[0]) < 1e-4       # measured 2.2e-5
    # The kick put ~0.2 J into the swing; what is not conserved stays a few % of it (the
    # strain energy of a cable whose unstretched length changes is not exactly a potential:
    # see taut.cdpr.control.plant).
    assert np.abs(E - E[0]).max() < 0.02


def test_velocity_control_without_model_error_tracks_within_1_mm(fk_stab):
    ref = pick_and_place(fk_stab, [[-0.6, 0, 1.0], [0.6, 0, 1.0]], dwell=0.2)
    run = simulate(fk_stab, ref, VelocityController(), backend="numpy")
    assert run.success, run.message
    assert np.abs(run.reference[:, 0] - run.reference[0, 0]).max() > 1.1   # it moved 1.2 m
    assert run.tracking_error.max() < 1e-3


def test_deployment_short_base_move_holds_the_platform(fk_stab):
    bm = BaseMotion.line(fk_stab, "active", (0.1, 0.0, 0.0), duration=1.0, start=0.1)
    run = simulate(fk_stab, _hold(fk_stab, HOLD, 1.3), VelocityController(), base_motion=bm,
                   backend="numpy")
    moved = run.base_poses[-1, 0, 0] - run.base_poses[0, 0, 0]
    assert abs(moved - 0.1) < 1e-9
    assert run.tracking_error.max() < 2e-3


@pytest.mark.slow  # ~4 s of CPU: the slow target (CI runs it)
def test_monte_carlo_batch_equals_single_runs(fk_stab):
    ref = pick_and_place(fk_stab, [[-0.3, 0, 1.0], [0.3, 0, 1.0]], dwell=0.1)
    errs = [ModelErrors(exit_offset=0.003, seed=s) for s in (1, 2)]
    mc = monte_carlo(fk_stab, ref, TorqueController(), errs, backend="numpy", settle=0.3)
    for i, e in enumerate(errs):
        one = simulate(fk_stab, ref, TorqueController(), model_errors=e, backend="numpy",
                       settle=0.3)
        assert mc.max_tracking_error[i] == pytest.approx(one.tracking_error.max(), rel=1e-9)
        assert mc.max_tension[i] == pytest.approx(one.tensions.max(), rel=1e-9)
        assert mc.min_tension[i] == pytest.approx(one.tensions.min(), rel=1e-9)


def test_diverging_plant_is_a_result_naming_the_time(fk_stab):
    run = simulate(fk_stab, _hold(fk_stab, HOLD, 1.0), TorqueController(), backend="numpy",
                   external_wrench=[0, 0, 5000.0, 0, 0, 0], settle=0.0)
    assert not run.success and run.status == "diverged"
    assert "diverged at t = " in run.message
    assert np.all(np.isfinite(run.poses))


def test_bad_input(fk_stab):
    ref = _hold(fk_stab, HOLD)
    with pytest.raises(InfeasiblePoseError, match="waypoints"):
        pick_and_place(fk_stab, [[0, 0, 1.0], [9.0, 0, 1.0]])
    with pytest.raises(InvalidInputError, match="speed"):
        pick_and_place(fk_stab, [[0, 0, 1.0], [1.0, 0, 1.0]], speed=0.0)
    with pytest.raises(InvalidInputError):
        pick_and_place(fk_stab, [[0, 0, np.nan], [1.0, 0, 1.0]])
    with pytest.raises(InvalidInputError, match="control_rate.*at least"):
        simulate(fk_stab, ref, VelocityController(), control_rate=50.0, backend="numpy")
    with pytest.raises(InvalidInputError, match="control_rate"):
        simulate(fk_stab, ref, VelocityController(), control_rate=-1.0)
    with pytest.raises(InvalidInputError, match="controller"):
        simulate(fk_stab, ref, "velocity")
    with pytest.raises(InvalidInputError, match="^backend: unknown backend 'fortran'"):
        simulate(fk_stab, ref, VelocityController(), backend="fortran")
    with pytest.raises(InvalidInputError, match="^profile: "):
        pick_and_place(fk_stab, [[0, 0, 1.0], [1.0, 0, 1.0]], profile="cubic")
    with pytest.raises(InvalidModelError, match="cable_stiffness"):
        DynamicsModel(cable_stiffness=0.0)
    with pytest.raises(InvalidInputError, match="length_gain"):
        VelocityController(length_gain=-1.0)
    with pytest.raises(InvalidInputError, match="exit_offset"):
        ModelErrors(exit_offset=-0.001)
    high = pick_and_place(fk_stab, [[0, 0, 1.0], [0, 0, 1.85]], dwell=0.1)
    with pytest.raises(InfeasiblePoseError, match=r"wrench-feasible workspace at t = "):
        simulate(fk_stab, high, TorqueController(), backend="numpy")


def test_pick_and_place_profiles_reach_the_speed(fk_stab):
    wp = [[-1.0, 0, 0.8], [1.0, 0, 0.8]]
    for profile in ("quintic", "trapezoidal"):
        ref = pick_and_place(fk_stab, wp, 1.0, profile=profile)
        v = np.linalg.norm(ref.velocities[:, :3], axis=1)
        assert v.max() == pytest.approx(1.0, abs=1e-3)
        # positions integrate the velocities
        assert np.allclose(np.gradient(ref.poses[:, 0], ref.times), ref.velocities[:, 0],
                           atol=5e-3)
        assert np.allclose(ref.poses[-1, :3], wp[-1])


@pytest.mark.slow
def test_paper_claim_velocity_vs_torque_with_5mm_exit_errors(fk_stab):
    """Both laws see what FASTKIT has (the default Sensing: encoders; the torque law's pose is
    estimated from them on the nominal model), so the tracking comparison is fair."""
    wp = [[-1.5, 0, 0.6], [-1.5, 0, 1.1], [1.5, 0, 1.1], [1.5, 0, 0.6]]
    ref = pick_and_place(fk_stab, wp, 1.0, dwell=0.5)
    me = ModelErrors(exit_offset=0.005, seed=0)
    vel = simulate(fk_stab, ref, VelocityController(), model_errors=me, sensing=Sensing())
    tor = simulate(fk_stab, ref, TorqueController(), model_errors=me, sensing=Sensing())
    assert vel.status == "infeasible"
    assert vel.slack_time > 0.1 and vel.worst_over_tension > 1.0
    assert tor.success, tor.message
    assert tor.tensions.min() >= tor.t_min.min() and tor.tensions.max() <= tor.t_max.max()
    assert tor.tracking_error.max() < vel.tracking_error.max()


@pytest.mark.slow
def test_deployment_active_base_moves_half_a_metre(fk_stab):
    """The physical drive: the active base on its wheels (plan_base_drive), the platform
    held low enough for a tension distribution to keep it upright; every law holds it."""
    from taut.cdpr import ComputedTorqueController, plan_base_drive
    low = np.array([0.3, 0.0, 0.7, 0.0, 0.0, 0.0])
    bm = BaseMotion.line(fk_stab, "active", (0.5, 0.0, 0.0), duration=5.0, start=0.2)
    plan = plan_base_drive(fk_stab, low, bm)
    assert plan.success, plan.message
    for ctl in (VelocityController(), TorqueController(), ComputedTorqueController()):
        run = simulate(plan.drive_robot, _hold(fk_stab, low, 5.5), ctl, base_motion=bm)
        assert run.base_poses[-1, 0, 0] - run.base_poses[0, 0, 0] == pytest.approx(0.5)
        assert run.success, run.message
        assert run.tracking_error.max() < 2e-3, ctl.name
        assert run.tipping_margin.min() >= 0.0, ctl.name


@pytest.mark.slow
def test_numba_and_numpy_backends_agree(fk_stab):
    pytest.importorskip("numba")
    ref = pick_and_place(fk_stab, [[-0.5, 0, 1.0], [0.5, 0, 1.0]], dwell=0.1)
    me = ModelErrors(exit_offset=0.005, length_offset=0.002, friction_scale=1.5, seed=4)
    for ctl in (VelocityController(), TorqueController()):
        a = simulate(fk_stab, ref, ctl, model_errors=me, backend="numba")
        b = simulate(fk_stab, ref, ctl, model_errors=me, backend="numpy")
        assert np.abs(a.poses - b.poses).max() < 1e-9
        assert np.abs(a.tensions - b.tensions).max() < 1e-6
        assert np.abs(a.motor_torques - b.motor_torques).max() < 1e-9


def test_tipping_monitor_moving_and_static_paths_agree(fk_stab):
    from taut.cdpr import cable_state
    from taut.cdpr.control.monitors import tipping_margins
    g = np.random.default_rng(2)
    P = np.column_stack([g.uniform(-1, 1, 30), np.zeros(30), g.uniform(0.7, 1.3, 30),
                         g.uniform(-0.1, 0.1, (30, 3))])
    st = cable_state(fk_stab, P)
    t = g.uniform(5, 45, (30, fk_stab.m))
    bp = np.repeat(np.array([b.pose for b in fk_stab.bases])[None], 30, axis=0)
    ex = np.broadcast_to(fk_stab.exits_world, (30, fk_stab.m, 3)).copy()
    static = tipping_margins(fk_stab, ex, st.unit, t, bp)
    ex2 = ex.copy()
    ex2[1:] += 0.0                                   # identical values, moving code path:
    bp2 = bp.copy()
    bp2[1:, 1, 2] += 2 * np.pi                       # same poses, not equal numbers
    moving = tipping_margins(fk_stab, ex2, st.unit, t, bp2)
    ref = -tipping_moments(fk_stab, P, t).moments
    assert np.allclose(static, ref, atol=1e-9) and np.allclose(moving, ref, atol=1e-9)


def test_the_compiled_loop_uses_the_one_numba_set_up():
    """`backend` is the one name of the numba/numpy switch, and the compiled loop is built by
    taut._jit (no numba set-up of its own)."""
    import inspect

    import taut._jit
    from taut.cdpr.control import _kernel

    for f in (simulate, monte_carlo):
        params = inspect.signature(f).parameters
        assert params["backend"].default == "auto" and "engine" not in params
    assert _kernel.jit is taut._jit.jit and "import numba" not in inspect.getsource(_kernel)
