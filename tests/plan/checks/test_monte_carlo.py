"""Monte Carlo of a plan under robot position error: the replay through the quasi-static
simulation and what it counts."""

import pytest

from taut.plan import _tol
from taut.plan import plan_robustness
from taut.plan.checks.robustness import replay

from ..test_plan import EXAMPLES


def test_exact_replay_matches_the_verification(paper_corridor_plan):
    sc, r = paper_corridor_plan
    t = replay(sc, r.robots, r.object)
    assert not t.failed and not t.unsafe
    assert t.deviation < 1e-6 * sc.team.sheet.size
    assert t.height_margin == pytest.approx(min(r.verification.min_height_margin,
                                                r.object[:, 2].min()), abs=1e-9)
    # The replay measures at the samples; the verification proves the least clearance of
    # the continuous motion (a lower bound), within the sampling's robot motion of it.
    assert (r.verification.min_clearance - 1e-7 <= t.clearance
            <= r.verification.min_clearance + _tol.SAMPLE_STEP)
    assert t.extension == pytest.approx(-r.verification.min_sheet_slack, abs=1e-12)


def test_a_robot_pushed_into_a_wall_is_a_collision_and_a_pair_pulled_apart_a_tear(
        paper_corridor_plan):
    sc, r = paper_corridor_plan
    bad = r.robots.copy()
    bad[5, 0, 1] = 1.0 - 0.5 * sc.team.robot_radius         # half inside the wall y = 1
    assert replay(sc, bad, r.object).collision
    far = r.robots.copy()
    far[7, 0] += 10.0
    t = replay(sc, far, r.object)
    assert t.torn and t.failed and t.extension > 9.0


@pytest.mark.slow  # ~2.3 s of CPU: the slow target (CI runs it)
def test_probabilities_follow_the_margins(paper_corridor_plan):
    sc, r = paper_corridor_plan
    small = plan_robustness(r, 0.005, 10, seed=2)       # the default 5 mm position accuracy
    assert small.tear_probability == 0.0 and small.worst_extension < 0
    assert small.failure_probability == 0.0 and small.collision_probability == 0.0
    # The plan holds the object exactly the height safety above the obstacles, so noise
    # makes it unsafe (below the safety) in most trials without any contact.
    assert small.unsafe_probability > 0.5 and small.contact_probability == 0.0
    assert 0 < small.worst_height_margin < sc.team.height_safety
    big = plan_robustness(r, 0.2, 10, seed=2)
    assert big.tear_probability > 0.5 and big.failure_probability >= big.tear_probability
    # 4 cm at every sample squeezes the compact formation until the object is lost.
    assert plan_robustness(r, 0.04, 5, seed=2).drop_probability > 0


def test_cli_reports_margins_and_robustness(capsys):
    import json

    from ..test_plan import _app
    yaml = str(EXAMPLES / "paper_corridor.yaml")
    rc = _app()(args=["plan", yaml, "--robustness", "0.005", "--trials", "3", "--json"],
                standalone_mode=False)
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["success"] and doc["sheet_margin"] == 0.01
    assert doc["margins"]["sheet_slack"] >= 0.01 - 1e-9
    assert doc["margins"]["clearance"] >= 0.2 - 1e-9           # robot radius + lateral
    rob = doc["robustness"]
    assert rob["trials"] == 3 and rob["sigma"] == 0.005 and rob["tear_probability"] == 0.0
    assert rob["worst_extension"] < 0
