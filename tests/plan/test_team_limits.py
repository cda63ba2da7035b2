"""Bounded work for planning teams (issue 11): too many robots are refused before any
allocation, a team that cannot hold its object is refused before any optimisation, and the
search budget is a sample count, so results do not depend on the machine's load."""

import numpy as np
import pytest
import yaml

import taut.plan.formations._problem as problem
from taut.cli import main
from taut.errors import InvalidInputError, PlanningError, ScenarioError
from taut.io.plan_scenario import plan_scenario_from_mapping
from taut.plan import Scenario, Team, World, plan
from taut.plan.world import MAX_TEAM_ROBOTS
from taut.sheet import Sheet, SheetTeam

from .test_plan import EXAMPLES, corridor


def _paper_mapping():
    return yaml.safe_load((EXAMPLES / "paper_corridor.yaml").read_text())


@pytest.mark.parametrize("n", [MAX_TEAM_ROBOTS + 1, 40, 1_000_000_000])
def test_regular_team_too_large_is_refused_before_the_sheet_is_built(n, monkeypatch):
    data = _paper_mapping()
    data["team"].pop("sheet", None)
    data["team"]["regular"] = {"n": n, "circumradius": 0.6}

    def no_sheet(*a, **k):              # a billion vertices would never be allocated
        raise AssertionError("Sheet.regular called for a refused team")
    monkeypatch.setattr(Sheet, "regular", staticmethod(no_sheet))
    with pytest.raises(ScenarioError) as e:
        plan_scenario_from_mapping(data)
    assert e.value.field == "team.regular.n" and f"got {n}" in e.value.problem


def test_team_size_limit_in_the_api_and_just_below_it():
    big = Sheet.regular(MAX_TEAM_ROBOTS + 1, 1.0)
    with pytest.raises(InvalidInputError) as e:
        Team(SheetTeam(big, 0.5), 0.05, 0.02, 0.02, 0.1, 0.3)
    assert e.value.field == "carrier"
    ok = Team(SheetTeam(Sheet.regular(MAX_TEAM_ROBOTS, 1.0), 0.5), 0.05, 0.02, 0.02, 0.1, 0.3)
    assert ok.n == MAX_TEAM_ROBOTS


def test_cli_refuses_a_huge_team_in_one_line(tmp_path, capsys):
    data = _paper_mapping()
    data["team"].pop("sheet", None)
    data["team"]["regular"] = {"n": 1_000_000_000, "circumradius": 0.6}
    f = tmp_path / "huge.yaml"
    f.write_text(yaml.safe_dump(data))
    rc = main(["plan", str(f)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert err[0].startswith("taut: error: team.regular.n:") and "at most" in err[0]


@pytest.mark.parametrize("n", [3, 8, MAX_TEAM_ROBOTS])
def test_team_that_cannot_hold_fails_before_any_optimisation(n, monkeypatch):
    # Robots 0.4 m wide at the corners of a sheet with 0.3 m sides: no two can stand at
    # their sheet distance, so the cheap pair test refutes it with no IK and no SLSQP.
    def no_ik(*a, **k):
        raise AssertionError("inverse kinematics run for a refutable team")
    monkeypatch.setattr(problem, "inverse_kinematics", no_ik)
    side = 0.3
    team = Team(SheetTeam(Sheet.regular(n, side / (2 * np.sin(np.pi / n))), 0.1), 0.2, 0.02,
                0.02, 0.1, 0.3)
    sc = Scenario(World([[0, -1], [6, -1], [6, 1], [0, 1]]), team, [1, 0], [5, 0])
    with pytest.raises(PlanningError) as e:
        plan(sc)
    assert e.value.field == "team" and "cannot hold the object" in e.value.problem


def test_the_cheap_test_never_refutes_a_team_that_can_hold():
    # Cross-check of the necessary condition against the full optimisation: a team whose
    # pairs are all wider than two robot radii gets a formation.
    from taut.plan import optimal_formation
    team = Team(SheetTeam(Sheet.regular(4, 0.6), 0.5), 0.1, 0.04, 0.04, 0.2, 0.5)
    assert optimal_formation(team, kind="compact") is not None


def test_result_does_not_depend_on_the_time_cap():
    # The budget that decides is the sample count: a generous wall-clock cap (which never
    # triggers) gives the identical plan, sample for sample.
    from taut.plan import Obstacle
    sc = corridor([Obstacle("low", 0.1, center=[3.0, 0.0], radius=0.1)], width=1.6)
    a = plan(sc, iterations=400)
    b = plan(sc, iterations=400, time_budget=3600.0)
    assert a.success == b.success and a.status == b.status
    if a.success:
        assert np.array_equal(a.robots, b.robots) and np.array_equal(a.times, b.times)


@pytest.fixture(scope="module")
def narrow_passage():
    """A tall cylinder leaving gaps of 0.55 m in the 2 m corridor, planned with 40 samples
    a run: (scenario, result), shared by the two tests that read this failure (one plan,
    ~1.6 s of CPU, instead of two)."""
    from taut.plan import Obstacle
    sc = corridor([Obstacle("wall-ish", 0.9, center=[3.0, 0.0], radius=0.45)])
    return sc, plan(sc, iterations=40)


def test_exhausted_budget_names_the_samples(narrow_passage):
    _, r = narrow_passage
    assert not r.success and r.status == "budget_exhausted"
    assert "40 samples per run" in r.message and "in all" in r.message


def test_iterations_must_be_positive():
    sc = corridor([])
    with pytest.raises(InvalidInputError) as e:
        plan(sc, iterations=0)
    assert e.value.field == "iterations"
    with pytest.raises(InvalidInputError) as e:
        plan(sc, time_budget=-1.0)
    assert e.value.field == "time_budget"


def test_budget_exhaustion_diagnoses_a_passage_too_narrow(narrow_passage):
    # Gaps of 0.55 m beside a tall cylinder in a 2 m corridor (perpendicular line: (2 -
    # 0.9) / 2): a robot with its clearance (0.4 m) fits, so nothing is proved, but the
    # triangle team's narrowest formation (the squeezed one included) is wider than that
    # less the clearance, so the message says so, without claiming impossibility.
    import re
    from taut.plan.formations.library import _library, _min_width, _with_squeezed
    sc, r = narrow_passage
    assert r.status == "budget_exhausted" and r.certificate is None
    assert r.sheet_margin == 0.01                      # a failure carries the margin used
    m = re.search(r"obstacle 'wall-ish' .*? the widest passage is ([0-9.]+) m, less than "
                  r"the ([0-9.]+) m", r.message)
    assert m, r.message
    passage, need = float(m.group(1)), float(m.group(2))
    assert passage <= 0.55 + 1e-3 and passage > 0.4     # the perpendicular line is a bound
    compact, others, _ = _library(sc, r.sheet_margin)
    forms = _with_squeezed(sc, [compact, *others], True, r.sheet_margin)
    assert forms[-1].kind == "squeezed"
    narrowest = min(_min_width(f) for f in forms)
    assert need == pytest.approx(narrowest + 2 * sc.team.clearance, abs=1e-3)
    assert "not ruled out" in r.message
