"""The verifier proves the geometric rules for the continuous motion between samples, not
only at the samples (``taut.plan.checks._geometry``): a violation between two samples
fails the plan, valid plans still pass, and the proof is sound under dense resampling."""

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from taut.plan import Obstacle, resample_motion, verify_motion
from taut.plan import _tol

from ..test_plan import corridor

#: Tolerance of the rules, m (as the verifier's).
TOL = 1e-6


def rules_broken(scenario, robots, z):
    """Samples (indices) of ``robots`` (T, N, 2) breaking a geometric rule with the object
    at heights ``z`` (T,), checked here with shapely independently of the module."""
    world, team = scenario.world, scenario.team
    T, N = robots.shape[:2]
    pts = shapely.points(robots.reshape(-1, 2))
    bad = ~shapely.contains(world.geometry, pts).reshape(T, N).all(axis=1)
    clear = shapely.distance(world.geometry.exterior, pts)
    for o in world.obstacles:
        clear = np.minimum(clear, shapely.distance(o.geometry, pts))
    bad |= (clear.reshape(T, N) < team.clearance - TOL).any(axis=1)
    hulls = shapely.convex_hull(shapely.multipoints(robots))
    bad |= ~shapely.covers(world.geometry.buffer(TOL), hulls)
    for o in world.obstacles:
        bad |= shapely.intersects(hulls, o.geometry) & (z - o.height < team.height_safety - TOL)
    return np.flatnonzero(bad)


def triangle(centre, radius, angle=0.0):
    """Three robots on a circle of ``radius`` about ``centre``, robot 1 at ``angle`` + 90
    degrees, the others following counter-clockwise."""
    a = angle + np.pi / 2 + 2 * np.pi / 3 * np.arange(3)
    return np.asarray(centre, float) + radius * np.column_stack([np.cos(a), np.sin(a)])


def no_claim(robots):
    return np.full((len(robots), 3), np.nan)


def post_corridor(y_post, radius=0.02, height=1.0):
    return corridor([Obstacle("post", height, center=[3.0, y_post], radius=radius)])


def passing(step):
    """A triangle (robot 1 on top, at y = 0.5) translated along the corridor axis in steps
    of ``step`` m, so that robot 1 passes x = 3 between two samples."""
    xs = np.arange(1.0, 5.01, step)
    return np.array([triangle([x, 0.0], 0.5) for x in xs])


def turning_past(height):
    """A triangle turning by 120 degrees in one step next to a post of ``height`` (m) that
    its hull sweeps between the samples, its robots passing 0.22 m from it."""
    centre, r = np.array([3.0, 0.0]), 0.55
    post = centre + 0.31 * np.array([np.cos(np.pi / 6), np.sin(np.pi / 6)])
    sc = corridor([Obstacle("post", height, center=post, radius=0.02)])
    return sc, np.array([triangle(centre - [0.2, 0.0], r), triangle(centre, r),
                         triangle(centre, r, 2 * np.pi / 3)])


# ------------------------------------------------------------------ refused between samples


def test_robot_grazing_a_post_between_samples_is_refused():
    sc = post_corridor(0.6)               # robot 1's straight track passes 0.08 m from it
    robots = passing(0.6)                 # samples 0.3 m either side of the post
    check = verify_motion(sc, robots, no_claim(robots))
    assert not check.success
    k = int(np.flatnonzero(robots[:, 0, 0] < 3.0)[-1])       # the interval passing x = 3
    assert check.message.startswith("robot 1 only ")
    assert check.message.endswith(f"from a wall or obstacle between samples {k} and {k + 1}")
    # The samples alone meet every rule: the old sample-only check passed this motion.
    z = check.object[:, 2]
    assert np.all(np.isfinite(z)) and np.ptp(z) < 1e-9       # carried rigidly
    assert len(rules_broken(sc, robots, z)) == 0
    # Dense samples show the violation the proof found.
    dense, _ = resample_motion(robots, no_claim(robots), 50)
    assert len(rules_broken(sc, dense, np.full(len(dense), z[0])))


def test_hull_sweeping_over_a_tall_post_while_turning_is_refused():
    # A turn of 120 degrees in one step: the triangle ends where it started (robots
    # permuted), clear of the post, but sweeps its circumcircle, over the post, between.
    sc, robots = turning_past(1.0)
    check = verify_motion(sc, robots, no_claim(robots))
    assert not check.success
    assert check.message.startswith("object only ")
    assert "above obstacle 'post' between samples 1 and 2" in check.message
    # Samples alone (and the robots everywhere) are clear: only the hull breaks a rule.
    z = check.object[:, 2]
    assert np.all(np.isfinite(z)) and z.max() < 1.0 - sc.team.height_safety
    assert len(rules_broken(sc, robots, z)) == 0
    dense, _ = resample_motion(robots, no_claim(robots), 50)
    pts = shapely.points(dense.reshape(-1, 2))
    obstacle = sc.world.obstacles[0].geometry
    assert shapely.distance(obstacle, pts).min() > sc.team.clearance
    assert len(rules_broken(sc, dense, np.full(len(dense), z[0]))) > 0


def test_formation_change_grazing_a_post_is_refused():
    """Straight robot motion (not rigid): robot 1 alone swings past a post."""
    base = triangle([3.0, 0.0], 0.4)
    sc = corridor([Obstacle("post", 1.0, center=[3.0, 0.55], radius=0.02)])
    a, b = base.copy(), base.copy()
    a[0], b[0] = [2.75, 0.45], [3.25, 0.45]  # 0.25 m from the post, 0.08 m half-way
    robots = np.array([a, b])
    check = verify_motion(sc, robots, no_claim(robots))
    assert not check.success and "between samples 0 and 1" in check.message
    assert len(rules_broken(sc, robots, check.object[:, 2])) == 0
    assert check.message.startswith("robot 1 only ")


def test_unproved_interval_is_refused_at_the_depth_limit(monkeypatch):
    sc, robots = turning_past(0.05)       # a low post: the turn is valid
    check = verify_motion(sc, robots, no_claim(robots))
    assert check.success, check.message
    assert check.min_height_margin < np.inf               # the post passed beneath
    monkeypatch.setattr(_tol, "PROOF_DEPTH", 0)
    check = verify_motion(sc, robots, no_claim(robots))
    assert not check.success
    assert check.message.startswith("the motion could not be proved clear of walls and "
                                    "obstacles between samples 1 and 2")


# ------------------------------------------------------------------ valid motions pass


def test_clearance_between_samples_is_the_continuous_one():
    """A motion proved only after bisection passes, and its least clearance is the
    continuous motion's (robot 1 passes the post at 0.23 m), not the samples' (0.3 m)."""
    sc = post_corridor(0.75)
    robots = passing(0.6)
    check = verify_motion(sc, robots, no_claim(robots))
    assert check.success, check.message
    o = sc.world.obstacles[0]
    r_out = o.mec_radius
    assert 0.25 - r_out - _tol.CLEARANCE_ACCURACY <= check.min_clearance <= 0.25 - o.radius
    dense, _ = resample_motion(robots, no_claim(robots), 200)
    assert len(rules_broken(sc, dense, np.full(len(dense), check.object[0, 2]))) == 0


def test_gliding_along_a_wall_at_the_clearance_passes():
    """Robot 1 runs 4 m along the wall exactly at the clearance: its straight path is
    measured exactly, so the motion is proved without pieces shorter than its slack."""
    sc = corridor([])
    xs = np.arange(1.0, 5.0, _tol.SAMPLE_STEP)
    robots = np.array([triangle([x, 0.3], 0.5) for x in xs])   # robot 1 at y = 0.8
    check = verify_motion(sc, robots, no_claim(robots))
    assert check.success, check.message
    assert check.min_clearance == pytest.approx(sc.team.clearance, abs=1e-9)


def test_hull_gliding_past_a_tall_fin_passes():
    """A tall fin 1 um under the hull's lower edge while the team glides along it: the
    swept hull is measured exactly, so the motion is proved at once."""
    fin = Obstacle("fin", 1.0, polygon=[[2.995, -0.9], [3.005, -0.9], [3.005, -0.250001],
                                        [2.995, -0.250001]])
    sc = corridor([fin])
    xs = np.arange(2.95, 3.05 + 1e-9, _tol.SAMPLE_STEP)
    robots = np.array([triangle([x, 0.0], 0.5) for x in xs])   # lower edge at y = -0.25
    check = verify_motion(sc, robots, no_claim(robots))
    assert check.success, check.message
    dense, _ = resample_motion(robots, no_claim(robots), 50)
    assert len(rules_broken(sc, dense, np.full(len(dense), check.object[0, 2]))) == 0


def test_paper_plan_passes_at_any_sampling(paper_corridor_plan):
    sc, r = paper_corridor_plan
    assert r.success, r.message
    check = verify_motion(sc, r.robots, r.object)
    assert check.success, check.message
    robots, obj = resample_motion(r.robots, r.object, 10)
    fine = verify_motion(sc, robots, obj)
    assert fine.success, fine.message
    assert fine.min_clearance == pytest.approx(check.min_clearance, abs=1e-6)
    assert check.min_clearance >= sc.team.clearance - TOL
    # The reported clearance is the continuous motion's: no denser sample is lower.
    dense, _ = resample_motion(r.robots, r.object, 50)
    assert check.min_clearance <= continuous_clearance(sc, dense) + 1e-12


# ------------------------------------------------------------------ soundness


def random_motion(seed):
    """A random triangle team moving rigidly in big steps (up to 0.8 m and 1.2 rad) along a
    corridor with posts, low and tall; None when the draw is unusable."""
    rng = np.random.default_rng(seed)
    ang = np.pi / 2 + 2 * np.pi / 3 * np.arange(3) + rng.uniform(-0.25, 0.25, 3)
    form = rng.uniform(0.32, 0.55, 3)[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    d = np.linalg.norm(form[:, None] - form[None], axis=2)[np.triu_indices(3, 1)]
    if not (d.max() < 0.98 and d.min() > 0.35):
        return None
    obstacles: list[Obstacle] = []
    for i in range(int(rng.integers(1, 4))):
        c = rng.uniform([1.6, -0.9], [5.4, 0.9])
        rad = rng.uniform(0.02, 0.12)
        if all(np.linalg.norm(c - o.center) > rad + o.radius + 0.05 for o in obstacles) \
                and abs(abs(c[1]) - 1.0) > rad + 0.01 \
                and min(np.linalg.norm(c - [0.8, 0.0]), np.linalg.norm(c - [5.2, 0.0])) > rad:
            obstacles.append(Obstacle(f"o{i}", rng.choice([0.05, 1.0]), center=c,
                                      radius=rad))
    pos, heading, poses = np.array([1.0, rng.uniform(-0.3, 0.3)]), 0.0, []
    for _ in range(int(rng.integers(3, 8))):
        c, s = np.cos(heading), np.sin(heading)
        poses.append(pos + form @ np.array([[c, s], [-s, c]]))
        pos = pos + [rng.uniform(0.1, 0.8), rng.uniform(-0.15, 0.15)]
        pos[1] = np.clip(pos[1], -0.35, 0.35)
        heading += rng.uniform(-1.2, 1.2)
    return corridor(obstacles), np.array(poses)


def continuous_clearance(scenario, dense):
    """Least robot clearance over the samples ``dense`` (T, N, 2), m."""
    pts = shapely.points(dense.reshape(-1, 2))
    clear = shapely.distance(scenario.world.geometry.exterior, pts)
    for o in scenario.world.obstacles:
        clear = np.minimum(clear, shapely.distance(o.geometry, pts))
    return float(clear.min())


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_proved_motion_is_clear_at_any_density(seed):
    case = random_motion(seed)
    assume(case is not None)
    sc, robots = case
    check = verify_motion(sc, robots, no_claim(robots))
    if not check.success:
        return
    dense, _ = resample_motion(robots, no_claim(robots), 50)
    z = np.full(len(dense), check.object[0, 2])          # rigid: the object's height holds
    assert np.allclose(check.object[:, 2], z[0])
    assert len(rules_broken(sc, dense, z)) == 0
    assert check.min_clearance <= continuous_clearance(sc, dense) + 1e-12


def test_the_soundness_draws_are_not_vacuous():
    """Motions drawn as in the soundness property pass, and others that pass at their
    samples are refused between them."""
    outcome = []
    for seed in range(60):
        case = random_motion(seed)
        if case is None:
            continue
        sc, robots = case
        check = verify_motion(sc, robots, no_claim(robots))
        outcome.append("proved" if check.success else
                       "between" if "between samples" in check.message else "samples")
    assert outcome.count("proved") >= 10 and outcome.count("between") >= 2, outcome
