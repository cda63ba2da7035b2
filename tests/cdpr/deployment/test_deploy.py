"""Deployment planning of FASTKIT's mobile bases, and the `twist-set` / `deploy` commands."""

import json
from dataclasses import replace

import numpy as np
import pytest
import typer
from scipy.optimize import linprog

from taut.cdpr import (Base, Cable, CableRobot, Platform, cable_state, external_wrench_box, distribute_tensions, gravity_wrench,
                       grid_points, tipping_moments, with_stabilisers, wrench_feasible)
from taut.cdpr import (lift_bound, place_bases, plan_deployment, tallest_workspace,
                              upward_force_bound, workspace_box)
from taut.cdpr import as_poses
from taut.cdpr import available_twist_set
from taut.cli import main as taut_main
from taut.cli.cdpr_motion import add_commands
from taut.errors import InvalidInputError, TautError

# FASTKIT's 5 m long workspace (x), as a thin 0.1 m deep slab, 0.8 m high: a part of the
# preset's assumed 5 m x 2 m box that the 45 N cables can hold with the 7 kg payload.
BOX = np.array([[-2.5, -0.05, 0.2], [2.5, 0.05, 1.0]])
TWIST = np.array([1.0, 0, 0, 0, 0, 0])          # the paper's 1 m/s platform speed
# A 5 m long x 2 m high workspace (the paper's size; its position z 0.2-2.2 m is the
# preset's assumption), same slab.
FULL = np.array([[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]])
WEIGHT = 12.0 * 9.81                             # 5 kg platform + 7 kg payload, N


@pytest.fixture(scope="module")
def deployment():
    """A real (seeded) deployment search: heavy, so only `slow` tests use it."""
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    return plan_deployment(robot, BOX, required_twist=TWIST, maxiter=3, popsize=5,
                           grid=(6, 2, 3), verify_grid=(11, 3, 5), seed=0)


@pytest.mark.slow
def test_fastkit_deployment_is_verified_with_tipping(deployment):
    res = deployment
    assert res.success and res.status == "ok" and res.message.startswith("verified")
    assert res.margin > 0 and res.twist_margin > 0
    # independent re-check on a different, finer grid of the box with the issue-5 tests
    pts, _ = grid_points(BOX, (21, 3, 9))
    assert wrench_feasible(res.robot, pts, tipping=True).all()
    # ... and with explicit tensions: an LP distribution that respects tipping, whose
    # tensions are within limits and whose edge moments are all <= 0
    tr = distribute_tensions(res.robot, pts[::7], "lp_min_sum", tipping=True)
    assert tr.success.all()
    assert np.all(tr.tensions >= res.robot.t_min - 1e-6)
    assert np.all(tr.tensions <= res.robot.t_max + 1e-6)
    tm = tipping_moments(res.robot, pts[::7], tr.tensions)
    assert tm.stable.all()
    # the required twist is available everywhere
    assert available_twist_set(res.robot, pts).contains(TWIST).all()
    # bases actually moved to the planned poses
    for b in res.robot.bases:
        np.testing.assert_allclose(b.pose, res.base_poses[b.name])


def test_model_placement_is_worse():
    """The shipped placement (bases at +-3 m) is not wrench-feasible over this box with
    tipping: the planner improved on it."""
    from taut.io.cdpr_model import load_cdpr_model
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    pts, _ = grid_points(BOX, (11, 3, 5))
    assert not wrench_feasible(robot, pts, tipping=True).all()


@pytest.mark.slow
def test_full_height_box_reports_why(fastkit):
    """With the 7 kg payload and 45 N cables no placement holds the platform 2 m high over
    5 m: the planner says so and names the worst point."""
    res = plan_deployment(with_stabilisers(fastkit), [[-2.5, -0.05, 0.0],
                                                            [2.5, 0.05, 2.0]],
                          maxiter=1, popsize=4, grid=(5, 1, 3), verify_grid=(5, 2, 3))
    assert not res.success
    assert res.margin < 0
    assert "not wrench-feasible with tipping" in res.message
    assert res.status == "budget_exhausted"
    assert not res.point_feasible.all()


def test_place_bases(fastkit):
    r = place_bases(fastkit, {"active": (-3.5, 0.2, 0.1)})
    assert np.allclose(r.bases[0].pose, (-3.5, 0.2, 0.1))
    assert np.allclose(r.bases[1].pose, fastkit.bases[1].pose)
    assert r.bounds[0, 0] < fastkit.bounds[0, 0]
    with pytest.raises(InvalidInputError):
        place_bases(fastkit, {"ghost": (0, 0, 0)})


def test_workspace_validation(fastkit):
    assert workspace_box([-1, 1, -0.1, 0.1, 0.5, 1.0]).shape == (2, 3)
    with pytest.raises(InvalidInputError, match="no volume"):
        workspace_box([[-2.5, 0.0, 0.2], [2.5, 0.0, 2.2]])
    with pytest.raises(InvalidInputError, match="no volume"):
        workspace_box([1, -1, 0, 1, 0, 1])
    with pytest.raises(InvalidInputError, match="NaN"):
        workspace_box([0, 1, 0, 1, 0, float("nan")])
    with pytest.raises(InvalidInputError):
        plan_deployment(fastkit, BOX, required_twist=[1.0, 0.0])


def _app():
    app = typer.Typer()
    sub = typer.Typer()
    add_commands(sub)
    app.add_typer(sub, name="cdpr")
    return app


def _run(args, capsys):
    _app()(args=args, standalone_mode=False)
    return capsys.readouterr().out


def test_cli_twist_set(capsys, tmp_path):
    out = json.loads(_run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0",
                           "--json", "--plot", str(tmp_path / "ats.png")], capsys))
    assert out["moving"] == ["active"]
    assert all(a >= b - 1e-9 for a, b in zip(out["positive"], out["bases_fixed"]["positive"]))
    assert (tmp_path / "ats.png").stat().st_size > 1000
    nav = json.loads(_run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0",
                           "--mode", "navigation", "--json"], capsys))
    assert nav["positive"][0] == pytest.approx(0.2) and nav["positive"][2] == 0.0
    text = _run(["cdpr", "twist-set", "fastkit", "--pose", "0.3", "0", "1.0"], capsys)
    assert "vx" in text and "fixed" in text


@pytest.mark.parametrize("args, field", [
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--moving", "ghost"], "mode.moving"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--mode", "fly"], "mode"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--cable-speed", "-1"], "--cable-speed"),
    (["twist-set", "fastkit", "--pose", "nan", "0", "1"], "pose"),
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "0", "0.2", "1"], "workspace"),
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "nan", "0.2", "1"], "workspace"),
    (["deploy", "nosuchmodel", "--workspace", "-1", "1", "-1", "1", "0.2", "1"], "model"),
])
def test_cli_errors(args, field):
    with pytest.raises(TautError) as exc:
        _app()(args=["cdpr", *args], standalone_mode=False)
    assert exc.value.field == field


class _StubPlanner:
    """Stands in for `plan_deployment` in CLI tests (the CLI is under test, not the
    optimiser): records its arguments and returns a fixed placement, feasible or not."""

    def __init__(self, success):
        self.success = success
        self.calls = []

    def __call__(self, robot, box, **kwargs):
        from taut.cdpr import DeploymentResult, lift_bound
        self.calls.append((robot, np.asarray(box), kwargs))
        poses = {"active": np.array([-3.4, 0.0, 0.0]), "passive": np.array([3.4, 0.0, np.pi])}
        rr = place_bases(robot, poses)
        pts, _ = grid_points(box, (3, 2, 2))
        pf = np.ones(len(pts), bool) if self.success else np.arange(len(pts)) % 3 != 0
        return DeploymentResult(self.success, "ok" if self.success else "budget_exhausted",
                                "verified" if self.success else "best placement found: stub",
                                poses, rr, 1.5 if self.success else -0.5,
                                0.9 if kwargs.get("required_twist") is not None else None,
                                pts, np.where(pf, 1.5, -0.5), pf, np.asarray(box), 42,
                                lift_bound(robot, box))


@pytest.mark.parametrize("success", [True, False])
def test_cli_deploy(capsys, tmp_path, monkeypatch, success):
    stub = _StubPlanner(success)
    monkeypatch.setattr("taut.cdpr.plan_deployment", stub)
    code = taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-1.0", "1.0", "-0.05",
                      "0.05", "0.4", "0.9", "--stabilisers", "--maxiter", "1", "--json",
                      "--plot", str(tmp_path / "d.png")])
    out = json.loads(capsys.readouterr().out)
    assert code == (0 if success else 1)
    assert out["feasible"] is success and out["refuted"] is False
    assert out["points"] == 12 and out["feasible_points"] == (12 if success else 8)
    assert out["evaluations"] == 42 and out["margin"] == (1.5 if success else -0.5)
    assert out["base_poses"] == {"active": [-3.4, 0.0, 0.0], "passive": [3.4, 0.0, 3.1416]}
    assert out["message"] == ("verified" if success else "best placement found: stub")
    assert out["lift_bound"]["refutes"] is False
    assert (tmp_path / "d.png").stat().st_size > 1000
    # the CLI passed its settings through and deployed the stabilisers
    robot, box, kwargs = stub.calls[0]
    np.testing.assert_array_equal(box, [[-1.0, -0.05, 0.4], [1.0, 0.05, 0.9]])
    assert kwargs["maxiter"] == 1 and "seed" not in kwargs      # the library's default seed
    assert all(b.stabilisers_deployed for b in robot.bases if b.mobile)


def test_cli_deploy_text_with_external_wrench(capsys, monkeypatch):
    stub = _StubPlanner(False)
    monkeypatch.setattr("taut.cdpr.plan_deployment", stub)
    code = taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-0.5", "0.5", "-0.05",
                      "0.05", "0.5", "0.8", "--stabilisers", "--maxiter", "1",
                      "--external-wrench", "2", "2", "2", "0", "0", "0", "--twist", "0.5", "0",
                      "0", "0", "0", "0"])
    text = capsys.readouterr().out
    assert code == 1
    assert "NOT FOUND" in text.splitlines()[0]
    assert "active: x=-3.4 m" in text and "worst capacity margin -0.5 over 12 points" in text
    assert "best placement found: stub" in text
    _, _, kwargs = stub.calls[0]
    # a 2 N x 2 N x 2 N force box: 8 vertices of the extra external wrench
    assert kwargs["external_wrench"].shape == (8, 6)
    np.testing.assert_array_equal(np.abs(kwargs["external_wrench"][:, :3]), 2.0)
    np.testing.assert_array_equal(kwargs["required_twist"], [0.5, 0, 0, 0, 0, 0])


@pytest.mark.slow
def test_cli_deploy_real_search_is_verified(capsys):
    """The real optimiser behind the CLI, on a box it deploys (pinned: exit 0)."""
    code = taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-1.0", "1.0", "-0.05",
                      "0.05", "0.4", "0.9", "--stabilisers", "--maxiter", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["feasible"] is True
    assert out["feasible_points"] == out["points"] > 0

# --- placement-independent lift certificate -------------------------------------------

def test_certificate_refutes_the_paper_box_only(fastkit):
    """No placement can hold platform + payload over the top of the 5 m x 2 m box (preset
    exits at 2.40 / 2.25 m),
    while the 0.8 m high box (where a verified deployment exists) is not refuted."""
    full = lift_bound(fastkit, FULL)          # ~0.4 s of CPU: computed once, reused below
    for lb in (full, lift_bound(fastkit, fastkit.desired_workspace)):
        assert lb.refutes and lb.bound < lb.required
        assert lb.required == pytest.approx(WEIGHT) and lb.weight == pytest.approx(WEIGHT)
        assert lb.height == 2.2 and np.all(lb.points[:, 2] == 2.2)
        assert lb.per_cable.sum() == pytest.approx(lb.bound)
        assert lb.movable.all() and lb.shortfall > 40
        assert lb.explain().startswith("no placement can work: at z = 2.2 m")
    ok = lift_bound(fastkit, BOX)
    assert not ok.refutes and ok.bound > 2 * WEIGHT
    # tipping plays no part: stabilisers change nothing
    assert lift_bound(with_stabilisers(fastkit), FULL).bound == pytest.approx(full.bound)
    # the bound decreases with the height, and a downward disturbance raises the need
    zs = [lift_bound(fastkit, [[-2.5, -0.05, 0.2], [2.5, 0.05, z]]).bound
          for z in (1.0, 1.5, 2.0, 2.1)]
    assert np.all(np.diff(zs) < 0)
    d = lift_bound(fastkit, BOX, external_wrench=external_wrench_box(fastkit, [0, 0, 20, 0, 0, 0]))
    assert d.disturbance_down == 20 and d.required == pytest.approx(WEIGHT + 20)
    assert "disturbance adds up to 20.0 N downward" in d.explain()


def test_every_2m_high_box_clear_of_the_floor_is_refuted(fastkit):
    """The paper's "2 m high" workspace, wherever it starts: the preset's payload (a 0.15 m
    box whose centre hangs 0.175 m under the platform centre) reaches 0.25 m below the
    platform centre, so a box clear of the floor starts at z >= 0.25 m. Every such 2 m high
    box is refuted; the certificate stops refuting only for boxes starting below 0.04 m."""
    for zmin in (0.04, 0.1, 0.25, 0.5, 1.0):
        assert lift_bound(fastkit, [[-2.5, -0.05, zmin], [2.5, 0.05, zmin + 2.0]]).refutes
    assert not lift_bound(fastkit, [[-2.5, -0.05, 0.0], [2.5, 0.05, 2.0]]).refutes


def test_certificate_hand_checks(fastkit, point_mass):
    """One sample point: the best exit is right above each attachment (vertical cable,
    full t_max) for every cable whose exit is above its attachment point."""
    # z = 2.2: top attachments at 2.3 under the 2.40 m exits, bottom ones at 2.1 under 2.25
    lb = lift_bound(fastkit, [[0, 0, 1.0], [0, 0, 2.2]], samples=(1, 1))
    assert lb.bound == pytest.approx(8 * 45.0, rel=1e-9)
    # z = 2.34: top attachments (2.44) above the upper exits; bottom ones (2.24) still below
    lb = lift_bound(fastkit, [[0, 0, 1.0], [0, 0, 2.34]], samples=(1, 1))
    assert lb.bound == pytest.approx(4 * 45.0, rel=1e-9)
    # fixed frame: the actual exits are used, 4 cables of 60 N from (+-1, +-1, 3)
    z = 1.0
    lb = lift_bound(point_mass, [[0, 0, 0.5], [0, 0, z]], samples=(1, 1))
    assert not lb.movable.any()
    assert lb.bound == pytest.approx(4 * 60.0 * (3 - z) / np.sqrt(2 + (3 - z) ** 2))
    assert upward_force_bound(point_mass, [0, 0, z]) == pytest.approx(lb.bound)
    with pytest.raises(InvalidInputError):
        lift_bound(fastkit, BOX, samples=(0, 3))
    with pytest.raises(InvalidInputError, match="lower corner above upper corner"):
        lift_bound(fastkit, [[0, 0, 1.0], [0, 0, 0.5]])


def _wide(robot):
    """The robot with a frame box large enough for any sample point (statics unchanged)."""
    return replace(robot, bounds=[[-20, -20, 0], [20, 20, 5]])


def _lp_lift(robot, points):
    """Per point: (LP max of the total upward cable force within tension limits only,
    LP max of the upward force with the other wrench components balancing the weight or
    NaN when they cannot)."""
    P = as_poses(robot, points, check_bounds=False)
    st = cable_state(robot, P, validated=True)
    wg = gravity_wrench(robot, st.R)
    bounds = list(zip(robot.t_min, robot.t_max))
    free, eq = [], []
    others = [k for k in range(robot.dof) if k != 2]
    for W, w in zip(st.W, wg):
        a = linprog(-W[2], bounds=bounds, method="highs")
        free.append(-a.fun)
        b = linprog(-W[2], A_eq=W[others], b_eq=-w[others], bounds=bounds, method="highs")
        eq.append(-b.fun if b.status == 0 else np.nan)
    return np.array(free), np.array(eq)


def test_certificate_is_sound_for_random_placements(fastkit):
    """Cross-checks against the exact statics for seeded random placements: where the
    certificate refutes, the exact test (tipping off) fails at some top-face point; and
    everywhere the LP lift never exceeds the per-point bound, whose mean over the top face
    never exceeds the placement-independent bound."""
    g = np.random.default_rng(7)
    full = lift_bound(fastkit, FULL, samples=(21, 3))
    assert full.refutes
    for trial in range(8):
        poses = np.array([[g.uniform(-4.0, -2.6), g.uniform(-0.5, 0.5), g.uniform(-0.6, 0.6)],
                          [g.uniform(2.6, 4.0), g.uniform(-0.5, 0.5),
                           np.pi + g.uniform(-0.6, 0.6)]])
        if trial == 0:
            poses[:, 0] = (-2.2, 2.2)       # exits inside the box's x range
        rr = _wide(place_bases(fastkit, poses))
        assert not wrench_feasible(rr, full.points, tipping=False).all()
        # a random box (x extent, height) and the LP maxima for this placement
        x0 = g.uniform(-2.5, 1.0)
        box = [[x0, -0.1, 0.2], [x0 + g.uniform(0.3, 3.0), 0.1, g.uniform(0.8, 2.3)]]
        lb = lift_bound(fastkit, box, samples=(9, 3))
        free, eq = _lp_lift(rr, lb.points)
        pb = upward_force_bound(rr, lb.points)
        assert np.all(free <= pb + 1e-6)
        assert np.all(eq[np.isfinite(eq)] <= free[np.isfinite(eq)] + 1e-6)
        assert free.mean() <= lb.bound + 1e-6
        assert np.all(lb.per_cable >= upward_force_bound_terms(rr, lb.points).mean(0) - 1e-9)


def upward_force_bound_terms(robot, points):
    """Per-cable terms f_i(d_i) at the actual placement, written out independently."""
    att = points[:, None, :] + robot.attach_local[None]
    v = robot.exits_world[None] - att
    c = np.maximum(v[..., 2], 0.0)
    return robot.t_max * c / np.sqrt(v[..., 0] ** 2 + v[..., 1] ** 2 + c ** 2 + 1e-300)


def test_certificate_is_attained_with_one_exit_per_base():
    """With one exit per mobile base every exit can be put anywhere, so the bound must be
    attained: bases at the certificate's exit positions give, by LP, a mean lift over the
    top face equal to the bound; any other placement gives less."""
    fp = [[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]]
    bases = tuple(Base(f"b{i}", {"E": (0.0, 0.0, 2.0 + 0.2 * i)}, pose=(0.0, 0.0, 0.0),
                       mobile=True, mass=30.0, footprint=fp) for i in range(4))
    robot = CableRobot(bases, Platform({"P": (0.0, 0.0, 0.0)}, mass=4.0),
                       tuple(Cable(f"C{i}", f"b{i}", "E", "P", 1.0, 30.0 + 5 * i)
                             for i in range(4)), bounds=[[-20, -20, 0], [20, 20, 5]])
    box = [[-1.0, -0.5, 0.5], [1.5, 0.5, 1.6]]
    lb = lift_bound(robot, box, samples=(7, 5))
    best = place_bases(robot, np.column_stack([lb.exit_xy, np.zeros(4)]))
    free, _ = _lp_lift(_wide(best), lb.points)
    # equal up to the branch-and-bound tolerance (1e-5 t_max per cable)
    assert lb.bound - 1e-5 * robot.t_max.sum() <= free.mean() <= lb.bound + 1e-9
    g = np.random.default_rng(3)
    for _ in range(5):
        xy = lb.exit_xy + g.normal(scale=0.3, size=(4, 2))
        other = place_bases(robot, np.column_stack([xy, g.uniform(-3, 3, 4)]))
        assert _lp_lift(_wide(other), lb.points)[0].mean() < lb.bound


def test_certificate_is_nearly_attained(fastkit):
    """The bound is the maximum over free exits, not a loose estimate: exits placed at the
    certificate's optimal positions give the same per-cable value (through the exact
    per-point formula)."""
    lb = lift_bound(fastkit, FULL, samples=(21, 3))
    att = lb.points[:, None, :] + fastkit.attach_local[None]
    exits = np.column_stack([lb.exit_xy, fastkit.exits_world[:, 2]])
    v = exits[None] - att
    f = fastkit.t_max * np.maximum(v[..., 2], 0) / np.linalg.norm(v, axis=2)
    np.testing.assert_allclose(f.mean(0), lb.per_cable, rtol=0, atol=1e-3)
    # and no other exit position (dense search) beats it
    xs = np.linspace(-3, 3, 601)
    for i in (0, 2):
        q = lb.points[:, :2] + fastkit.attach_local[i, :2]
        c = fastkit.exits_world[i, 2] - 2.2 - fastkit.attach_local[i, 2]
        E = np.column_stack([xs + fastkit.attach_local[i, 0],
                             np.full_like(xs, fastkit.attach_local[i, 1])])
        d = np.linalg.norm(E[:, None] - q[None], axis=2)
        assert (45 * c / np.sqrt(d ** 2 + c ** 2)).mean(1).max() <= lb.per_cable[i] + 1e-9


def test_plan_deployment_stops_at_the_certificate(fastkit):
    res = plan_deployment(with_stabilisers(fastkit), FULL)
    assert not res.success and res.refuted and res.evaluations == 0
    assert res.status == "refuted"
    assert res.message.startswith("no placement can work: at z = 2.2 m the cables can lift "
                                 "at most ")
    assert "platform and payload weigh 117.7 N" in res.message
    assert res.lift_bound.refutes and res.lift_bound.bound < res.lift_bound.required
    assert res.points.shape == (0, 3) and res.point_feasible.shape == (0,)
    assert np.isnan(res.margin)


@pytest.mark.slow
def test_tallest_workspace_fastkit(fastkit):
    robot = with_stabilisers(fastkit)
    tw = tallest_workspace(robot, FULL, tol=0.25, maxiter=3, popsize=5, grid=(6, 2, 3),
                           verify_grid=(11, 3, 5))
    assert tw.deployment is not None and tw.deployment.success
    assert 0.6 < tw.height < tw.certified_limit < 2.2
    assert tw.tried and all(ok == (z <= tw.height) for z, ok in tw.tried)
    assert tw.failed_below > tw.height and len(tw.tried) <= 5
    np.testing.assert_allclose(tw.workspace, [[-2.5, -0.05, 0.2], [2.5, 0.05, tw.height]])
    # the certified limit really refutes, just below it does not
    assert tw.certificate.refutes and tw.certificate.height == tw.certified_limit
    assert not lift_bound(robot, [[-2.5, -0.05, 0.2],
                                  [2.5, 0.05, tw.certified_limit - 2e-3]]).refutes
    # independent re-check of the verified box on another grid, with tipping
    pts, _ = grid_points(tw.workspace, (17, 2, 7))
    assert wrench_feasible(tw.deployment.robot, pts, tipping=True).all()
    with pytest.raises(InvalidInputError):
        tallest_workspace(robot, FULL, tol=0)


def test_cli_deploy_refuted_exit_1(capsys, tmp_path):
    code = taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-2.5", "2.5", "-0.05",
                      "0.05", "0.2", "2.2"])
    out = capsys.readouterr().out
    assert code == 1
    assert "NOT FOUND" in out and "no placement can work: at z = 2.2 m" in out
    code = taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-2.5", "2.5", "-0.05",
                      "0.05", "0.2", "2.2", "--json", "--plot", str(tmp_path / "d.png")])
    js = json.loads(capsys.readouterr().out)
    assert code == 1
    assert js["feasible"] is False and js["refuted"] is True and js["points"] == 0
    assert js["lift_bound"]["refutes"] and js["lift_bound"]["bound"] < js["lift_bound"]["required"]
    assert js["plot"] is None and "nothing to plot" in js["plot_note"]
    assert not (tmp_path / "d.png").exists()
    # a malformed box is still an input error (exit 2)
    assert taut_main(["cdpr", "deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "0",
                      "0.2", "2.2"]) == 2


@pytest.mark.parametrize("args, field", [
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "0.1", "0.2", "1", "--seed", "-1"],
     "seed"),
    (["deploy", "fastkit", "--workspace", "-2.5", "2.5", "0", "0.1", "0.2", "1", "--maxiter",
      "-1"], "maxiter"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--base-speed", "-1"], "--base-speed"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--yaw-rate", "0"], "--yaw-rate"),
    (["twist-set", "fastkit", "--pose", "0", "0", "1", "--cable-speed", "0"], "--cable-speed"),
])
def test_cli_settings_errors(args, field):
    """Optimiser settings and speed limits a user can mistype: typed errors, no search run."""
    with pytest.raises(TautError) as exc:
        _app()(args=["cdpr", *args], standalone_mode=False)
    assert exc.value.field == field


def test_plan_deployment_rejects_bad_settings(fastkit):
    for kwargs in ({"seed": -1}, {"seed": 1.5}, {"maxiter": -2}, {"popsize": 0}):
        with pytest.raises(InvalidInputError) as exc:
            plan_deployment(fastkit, BOX, **kwargs)
        assert exc.value.field == next(iter(kwargs))
