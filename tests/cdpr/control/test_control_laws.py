"""Control laws (issue 26): computed torque, custom controllers on every engine and their
describe(), the gain rule for other control rates.

Tracking comparisons give every controller the same sensing (the default: encoders, pose
estimated on the nominal model); only tests named "ideal pose" hand a controller the truth.
"""

import json

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

from taut.cdpr import (CONTROLLERS, ComputedTorqueController, Controller, DynamicsModel,
                       ModelErrors,
                       Sensing, TorqueController, VelocityController, monte_carlo,
                       pick_and_place, reference_from_samples, simulate, tune_for_rate,
                       with_stabilisers)
from taut.cdpr.control.controllers import (DESIGN_LOOP_DELAY, JOINT_DELAY_PHASE, Measurement,
                                           loop_delay)
from taut.cdpr.kinematics.cables import rotation_matrices
from taut._jit import HAVE_NUMBA
from taut.errors import InvalidInputError

WP = [[-0.6, 0.0, 0.8], [0.6, 0.0, 1.0]]


@pytest.fixture(scope="module")
def fk_stab():
    from taut.io.cdpr_model import load_cdpr_model
    return with_stabilisers(load_cdpr_model("fastkit"))


@pytest.fixture(scope="module")
def ctx(fk_stab):
    """The nominal control context of a short move (built as simulate builds it)."""
    from taut.cdpr.control.simulate import _prepare
    ref = pick_and_place(fk_stab, WP, 1.0, dwell=0.1)
    return _prepare(fk_stab, ref, ComputedTorqueController(), None, None, 1000.0, None,
                    None, 1, None, 0.0).ctx


def _spatial_wrench(robot, ctx, p, R, v, w, a, alpha):
    """Cable wrench about P that moves the nominal body with (a, alpha) at (p, R, v, w),
    written independently of the controller: spatial inertia about P (parallel-axis
    inertia I_P = I_c - M [c]x [c]x, first moment M c) and Newton-Euler about P,
    f = M (a + alpha x c + w x (w x c) - g), n_P = I_P alpha + w x I_P w + M c x (a - g)."""
    M = ctx.mass
    c = R @ ctx.com_local
    Ic = R @ ctx.inertia_local @ R.T
    S = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
    IP = Ic - M * S @ S
    g = robot.gravity
    f = M * (a + np.cross(alpha, c) + np.cross(w, np.cross(w, c)) - g)
    n = IP @ alpha + np.cross(w, IP @ w) + M * np.cross(c, a - g)
    return np.r_[f, n]


@settings(max_examples=40, deadline=None)
@given(k=st.integers(0, 1500), dp=st.lists(st.floats(-0.002, 0.002), min_size=3, max_size=3),
       drot=st.lists(st.floats(-0.005, 0.005), min_size=3, max_size=3),
       dv=st.lists(st.floats(-0.02, 0.02), min_size=6, max_size=6))
def test_computed_torque_wrench_is_newton_euler_at_the_estimated_state(fk_stab, ctx, k, dp,
                                                                       drot, dv):
    """The tensions the law commands produce, through W at the *measured* pose, exactly the
    wrench of the platform's inverse dynamics there (an independent formulation about P)."""
    k = min(k, len(ctx.ref_poses) - 1)
    law = ComputedTorqueController()
    p = ctx.ref_poses[k, :3] + dp
    R = rotation_matrices(np.asarray(drot)[None])[0] @ ctx.R_ref[k]
    v, w = ctx.ref_vel[k, :3] + dv[:3], ctx.ref_vel[k, 3:] + dv[3:]
    speed = ctx.L0_dot[k] / ctx.dynamics.length_per_rad
    meas = Measurement(p[None], R[None], v[None], w[None], ctx.L0[k][None], speed[None],
                       np.full((1, fk_stab.m), np.nan))
    t = law.tensions(ctx, k, meas)[0]
    # the commanded accelerations of the law
    E = ctx.R_ref[k] @ R.T
    er = 0.5 * np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
    a = ctx.ref_acc[k, :3] + law.position_damping * (ctx.ref_vel[k, :3] - v) \
        + law.position_stiffness * (ctx.ref_poses[k, :3] - p)
    alpha = ctx.ref_acc[k, 3:] + law.rotation_damping * (ctx.ref_vel[k, 3:] - w) \
        + law.rotation_stiffness * er
    want = _spatial_wrench(fk_stab, ctx, p, R, v, w, a, alpha)
    r = (R @ ctx.attach.T).T
    u = ctx.exits[k] - p - r
    u /= np.linalg.norm(u, axis=1)[:, None]
    W = np.vstack([u.T, np.cross(r, u).T])
    # FASTKIT's planar layout has little lateral capacity: where the distribution must fix
    # a cable at a limit (or clip), W t = w need not hold; every other state must match
    assume(np.all(t > fk_stab.t_min + 1e-6) and np.all(t < fk_stab.t_max - 1e-6))
    assert np.allclose(W @ t, want, atol=1e-8 * max(1.0, np.abs(want).max()))


def test_computed_torque_at_the_reference_state_gives_the_reference_tensions(ctx):
    """On the reference state the law's online distribution is the one simulate
    precomputed along the reference (same closed form, same wrench)."""
    law = ComputedTorqueController()
    for k in (0, 400, 800, len(ctx.ref_poses) - 1):
        meas = Measurement(ctx.ref_poses[k, :3][None], ctx.R_ref[k][None],
                           ctx.ref_vel[k, :3][None], ctx.ref_vel[k, 3:][None], ctx.L0[k][None],
                           (ctx.L0_dot[k] / ctx.dynamics.length_per_rad)[None],
                           np.full((1, ctx.L0.shape[1]), np.nan))
        t = law.tensions(ctx, k, meas)[0]
        assert np.allclose(t, ctx.tensions[k], atol=5e-3), k


@pytest.mark.slow  # ~4 s of CPU: the slow target (CI runs it)
def test_computed_torque_tracks_with_the_ideal_pose_and_with_encoders(fk_stab):
    """Ideal pose (a study): sub-millimetre tracking. Encoders (what FASTKIT has) with 5 mm
    exit errors: inside the limits, the error carried by the pose estimate like the torque
    law's (both laws see the same sensing)."""
    ref = pick_and_place(fk_stab, WP, 1.0, dwell=0.1)
    ideal = simulate(fk_stab, ref, ComputedTorqueController(), sensing=Sensing(ideal_pose=True),
                     settle=0.3)
    assert ideal.success, ideal.message
    assert ideal.tracking_error.max() < 1e-3
    me = [ModelErrors(exit_offset=0.005, seed=s) for s in range(3)]
    ct = monte_carlo(fk_stab, ref, ComputedTorqueController(), me, settle=0.3)
    tq = monte_carlo(fk_stab, ref, TorqueController(), me, settle=0.3, backend="numpy")
    assert np.all(ct.min_tension >= 5.0) and np.all(ct.max_tension <= 45.0)
    assert np.all(ct.max_tracking_error > 1e-3)          # the geometry error is seen...
    assert np.all(ct.max_tracking_error < 3 * tq.max_tracking_error + 1e-3)   # ...like torque


class _Hold(Controller):
    """A custom law that is not a dataclass: joint-space PD on the encoder lengths in torque
    mode, with public gains, an array and a private attribute."""

    name = "hold"
    mode = "torque"

    def __init__(self) -> None:
        self.stiffness = 4.0e3                    # N/m of cable
        self.weights = np.ones(8)
        self._scratch = object()

    def command(self, ctx, k, meas):
        kl = ctx.dynamics.length_per_rad
        t = ctx.tensions[k] + self.weights * self.stiffness * (meas.L0 - ctx.L0[k])
        return kl * t / ctx.dynamics.efficiency


def test_describe_of_a_custom_controller_that_is_not_a_dataclass():
    d = _Hold().describe()
    assert d == {"name": "hold", "mode": "torque", "stiffness": 4.0e3, "weights": [1.0] * 8}
    json.dumps(d)
    assert ComputedTorqueController().describe()["name"] == "computed_torque"


def test_custom_and_computed_torque_run_on_every_engine(fk_stab):
    t = np.linspace(0.0, 0.1, 4)
    ref = reference_from_samples(fk_stab, t, np.tile([0.3, 0, 0.9, 0, 0, 0], (4, 1)))
    for law in (_Hold(), ComputedTorqueController()):
        runs = [simulate(fk_stab, ref, law, settle=0.1, backend=b) for b in _ENGINES]
        for run in runs:
            assert run.success, run.message
            assert run.tracking_error.max() < (1e-2 if law.name == "hold" else 2e-3)
            assert run.controller == law.describe()
        assert np.abs(runs[0].poses - runs[-1].poses).max() < 1e-9


#: Every engine this machine has (numba needs the package; tests/conftest.py compiles).
_ENGINES = ("numpy",) + (("numba",) if HAVE_NUMBA else ())


class _MyVelocity:
    """The velocity law re-implemented outside taut, not a Controller subclass (the bare
    protocol), with a describe() of its own."""

    name, mode = "my_velocity", "speed"

    def __init__(self, length_gain=20.0):
        self.length_gain = length_gain

    def command(self, ctx, k, meas):
        rate = ctx.L0_dot[k] + self.length_gain * (ctx.L0[k] - meas.L0)
        return rate / ctx.dynamics.length_per_rad

    def describe(self):
        return {"name": self.name, "mode": self.mode, "length_gain": self.length_gain,
                "note": "re-implementation"}


class _MyTorque(TorqueController):
    """The torque law through Python on every engine (a subclass is not compiled)."""

    name = "my_torque"

    def command(self, ctx, k, meas):
        return super().command(ctx, k, meas)


@pytest.mark.parametrize("engine", _ENGINES)
def test_a_custom_law_equal_to_a_built_in_gives_its_trajectory(fk_stab, engine):
    """A custom controller computing the built-in law's commands follows the built-in's
    trajectory on every engine (numba: controller in Python, plant compiled, against the
    fully compiled loop), with the errors and encoder sensing acting."""
    ref = pick_and_place(fk_stab, [[-0.1, 0, 1.0], [0.1, 0, 1.0]], 0.3, dwell=0.05)
    me = ModelErrors(exit_offset=0.005, winch=0.1, seed=3)
    opts = {"settle": 0.05, "duration": 0.2}            # the dwell and the start of the move
    for mine, theirs in ((_MyVelocity(), VelocityController()), (_MyTorque(), TorqueController())):
        a = simulate(fk_stab, ref, mine, model_errors=me, **opts, backend=engine)
        b = simulate(fk_stab, ref, theirs, model_errors=me, **opts, backend=engine)
        assert np.abs(a.poses - b.poses).max() < 1e-12
        assert np.abs(a.tensions - b.tensions).max() < 1e-9
        assert np.abs(a.motor_torques - b.motor_torques).max() < 1e-12
        assert a.controller["name"] == mine.name != b.controller["name"]
        if engine == "numba":                  # ... and the engines agree with each other
            c = simulate(fk_stab, ref, mine, model_errors=me, **opts, backend="numpy")
            assert np.abs(a.poses - c.poses).max() < 1e-9
            assert np.abs(a.tensions - c.tensions).max() < 1e-6


def test_a_bare_protocol_controller_batches_and_describes_itself(fk_stab):
    """An object that is not a Controller subclass: monte_carlo on every engine equals its
    single runs; its describe() is the result's controller and is in the result's JSON."""
    from taut.io.serialize import control_result_to_dict
    t = np.linspace(0.0, 0.2, 3)
    ref = reference_from_samples(fk_stab, t, np.tile([0.3, 0, 0.9, 0, 0, 0], (3, 1)))
    errs = [ModelErrors(exit_offset=0.003, seed=s) for s in (1, 2)]
    law = _MyVelocity()
    for engine in _ENGINES:
        mc = monte_carlo(fk_stab, ref, law, errs, settle=0.1, backend=engine)
        assert mc.controller == "my_velocity"
        one = simulate(fk_stab, ref, law, model_errors=errs[1], settle=0.1, backend=engine)
        assert mc.max_tension[1] == pytest.approx(one.tensions.max(), rel=1e-9)
    assert one.controller == law.describe()
    data = json.loads(json.dumps(control_result_to_dict(one)))
    assert data["controller"]["note"] == "re-implementation"


class _NoDescribe:
    name, mode = "plain", "speed"

    def __init__(self):
        self.gain = np.float64(2.0)

    def command(self, ctx, k, meas):
        return ctx.L0_dot[k] / ctx.dynamics.length_per_rad + 0.0 * meas.L0


@pytest.mark.parametrize("bad, field", [
    (VelocityController, "controller"),                       # the class, not an instance
    (object(), "controller"),                                 # no command
    (type("M", (_NoDescribe,), {"mode": "current"})(), "controller.mode"),
    (type("N", (_NoDescribe,), {"name": 3})(), "controller.name"),
    (type("D", (_NoDescribe,), {"describe": lambda self: "x"})(), "controller.describe"),
    (type("S", (_NoDescribe,), {"command": lambda self, c, k, m: np.zeros(3)})(),
     "controller.command"),
])
def test_a_controller_off_the_protocol_is_refused_by_field(fk_stab, bad, field):
    t = np.linspace(0.0, 0.05, 3)
    ref = reference_from_samples(fk_stab, t, np.tile([0.3, 0, 0.9, 0, 0, 0], (3, 1)))
    with pytest.raises(InvalidInputError, match=f"^{field}: "):
        simulate(fk_stab, ref, bad, settle=0.0, backend="numpy")


def test_describe_without_a_describe_method_is_the_default_one(fk_stab):
    from taut.cdpr.control.controllers import describe_controller
    d = describe_controller(_NoDescribe())
    assert d == {"name": "plain", "mode": "speed", "gain": 2.0} and type(d["gain"]) is float
    json.dumps(d)


def test_custom_controller_in_a_batch_equals_its_single_runs(fk_stab):
    """monte_carlo batches a custom (non-dataclass) law over plants like simulate runs it
    one at a time."""
    t = np.linspace(0.0, 0.2, 3)
    ref = reference_from_samples(fk_stab, t, np.tile([0.3, 0, 0.9, 0, 0, 0], (3, 1)))
    errs = [ModelErrors(exit_offset=0.002, winch=0.1, seed=s) for s in (5, 6)]
    mc = monte_carlo(fk_stab, ref, _Hold(), errs, settle=0.1)
    assert mc.controller == "hold"
    for i, e in enumerate(errs):
        one = simulate(fk_stab, ref, _Hold(), model_errors=e, settle=0.1)
        assert mc.max_tracking_error[i] == pytest.approx(one.tracking_error.max(), rel=1e-9)
        assert mc.min_tension[i] == pytest.approx(one.tensions.min(), rel=1e-9)
        assert mc.max_tension[i] == pytest.approx(one.tensions.max(), rel=1e-9)
    assert mc.max_tracking_error[0] != mc.max_tracking_error[1]     # the errors act


def test_custom_controller_runs_on_the_reference_integrator(fk_stab):
    ri = pytest.importorskip("taut.cdpr.control.reference_integrator")
    t = np.linspace(0.0, 0.05, 3)
    ref = reference_from_samples(fk_stab, t, np.tile([0.3, 0, 0.9, 0, 0, 0], (3, 1)))
    run = ri.reference_simulate(fk_stab, ref, _Hold(), settle=0.0)
    assert np.isfinite(run.tensions).all() and run.tracking_error.max() < 1e-2


# -- gains for other control rates -----------------------------------------------------------

def test_tune_for_rate_keeps_the_defaults_at_the_design_point():
    for cls in CONTROLLERS.values():
        c, s = tune_for_rate(cls(), Sensing(), 1000.0)
        assert c == cls() and s == Sensing()
    assert loop_delay(1000.0, 0.0) == pytest.approx(DESIGN_LOOP_DELAY)


@given(rate=st.floats(100.0, 2000.0), latency=st.floats(0.0, 0.02))
@settings(max_examples=50, deadline=None)
def test_tune_for_rate_keeps_the_phase_the_delay_costs(rate, latency):
    """Every bandwidth x loop delay stays at (or below) its design value, stiffnesses keep
    the damping ratio (Kd^2 / Kp constant)."""
    base = TorqueController()
    c, s = tune_for_rate(base, Sensing(latency=latency), rate)
    tau = loop_delay(rate, Sensing(latency=latency).latency)
    scale = min(1.0, DESIGN_LOOP_DELAY / tau)
    assert c.position_damping * tau <= base.position_damping * DESIGN_LOOP_DELAY * (1 + 1e-12)
    assert c.position_damping == pytest.approx(base.position_damping * scale)
    assert c.position_damping**2 / c.position_stiffness == pytest.approx(
        base.position_damping**2 / base.position_stiffness)
    assert s.velocity_filter == pytest.approx(30.0 * scale)
    J = DynamicsModel().rotor_inertia            # the collocated motor-speed damping loop
    assert c.joint_damping / J * tau <= max(JOINT_DELAY_PHASE, 2e-3 / J * tau) + 1e-12
    assert c.joint_damping == pytest.approx(min(2e-3, JOINT_DELAY_PHASE * J / tau))
    v, _ = tune_for_rate(VelocityController(tension_gain=200.0), Sensing(latency=latency), rate)
    assert v.tension_gain == pytest.approx(200.0 * scale)


def test_tune_for_rate_refuses_custom_controllers_and_bad_input():
    with pytest.raises(InvalidInputError, match="^controller: "):
        tune_for_rate(_Hold(), Sensing(), 200.0)
    with pytest.raises(InvalidInputError, match="^control_rate"):
        tune_for_rate(TorqueController(), Sensing(), -1.0)
    with pytest.raises(InvalidInputError, match="^sensing"):
        tune_for_rate(TorqueController(), "encoders", 200.0)


@pytest.mark.slow
def test_tuned_gains_hold_200_hz_with_5_ms_latency(fk_stab):
    """200 Hz, 5 ms latency, encoders, 5 mm exit errors: the 1 kHz gains leave the limits,
    the gains of the delay rule stay inside (torque law, velocity with tension feedback)."""
    wp = [[-1.5, 0, 0.6], [-1.5, 0, 1.1], [1.5, 0, 1.1], [1.5, 0, 0.6]]
    ref = pick_and_place(fk_stab, wp, 1.0, dwell=0.5)
    errs = [ModelErrors(exit_offset=0.005, seed=s) for s in range(5)]
    sens = Sensing(latency=0.005)
    for law in (TorqueController(), VelocityController(tension_gain=200.0)):
        raw = monte_carlo(fk_stab, ref, law, errs, sensing=sens, control_rate=200.0,
                          substeps=5)
        tuned, s = tune_for_rate(law, sens, 200.0)
        ok = monte_carlo(fk_stab, ref, tuned, errs, sensing=s, control_rate=200.0, substeps=5)
        assert np.mean((raw.min_tension >= 5) & (raw.max_tension <= 45)) == 0.0, law.name
        assert np.all((ok.min_tension >= 5) & (ok.max_tension <= 45)), law.name


def test_cli_computed_torque_with_latency_uses_the_gain_rule(capsys):
    from taut.cli import main
    args = ["cdpr", "simulate", "fastkit", "--stabilisers", "--waypoints",
            "-0.2,0,0.9; 0.2,0,0.9", "--dwell", "0.1", "--controller", "computed_torque"]
    assert main(args + ["--latency", "0.002", "--json"]) == 0      # s, as Sensing
    data = json.loads(capsys.readouterr().out)
    want, _ = tune_for_rate(ComputedTorqueController(), Sensing(latency=0.002), 1000.0)
    assert data["controller"] == json.loads(json.dumps(want.describe()))
    assert data["controller"]["position_damping"] == pytest.approx(34.0 * 1.5 / 3.5)
    assert main(args + ["--latency", "-1"]) == 2
    err = capsys.readouterr().err
    assert "--latency" in err and len(err.strip().splitlines()) == 1
