"""OMPL as a backend of the SE(2) search (``plan(..., search="ompl-...")``): same validity
checker, formations, crossing rules and verification as taut's own RRT-Connect."""

import json
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.errors import TautError
from taut.plan import Obstacle, plan, resample_motion, verify_motion
from taut.plan.se2._ompl import engine, unwrap_shortest

from ..test_plan import corridor
from .test_se2 import DETERMINISTIC, paper, tilted  # noqa: F401  (fixtures)


def _rechecked(sc, r) -> bool:
    """The plan passes verify_motion re-run at 10x its sampling."""
    rr, ro = resample_motion(r.robots, r.object, 10)
    return verify_motion(sc, rr, ro, sheet_margin=r.sheet_margin).success


# ------------------------------------------------------------------ no OMPL needed


def test_unknown_search_is_a_typed_error(paper):  # noqa: F811
    with pytest.raises(TautError) as e:
        plan(paper, search="ompl-rrt")
    assert e.value.field == "search" and "ompl-rrtconnect" in e.value.problem


def test_missing_extra_is_a_typed_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "ompl", None)         # import ompl now fails
    assert engine("rrtconnect") is None                     # the own search needs nothing
    with pytest.raises(TautError) as e:
        engine("ompl-rrtconnect")
    assert e.value.field == "search" and "plan-ompl" in e.value.problem


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-50, 50), min_size=2, max_size=12))
def test_unwrap_turns_the_short_way(psi):
    path = np.column_stack([np.zeros((len(psi), 2)), psi])
    out = unwrap_shortest(path)
    step = np.diff(out[:, 2])
    assert np.all(np.abs(step) <= np.pi + 1e-12)
    # Same headings up to whole turns.
    assert np.allclose(np.exp(1j * out[:, 2]), np.exp(1j * np.asarray(psi)), atol=1e-9)
    assert out[0, 2] == psi[0]


# ------------------------------------------------------------------ with OMPL


@pytest.fixture(scope="module")
def ompl():
    return pytest.importorskip("ompl")


def test_checked_motion_is_omplinterpolation(ompl, paper):  # noqa: F811
    """The straight motion PoseChecker.motion_valid checks (headings unwrapped the short
    way) is the curve OMPL's SE(2) interpolation follows."""
    from ompl import base as ob
    space = ob.SE2StateSpace()
    rng = np.random.default_rng(3)
    for _ in range(50):
        a = np.array([*rng.uniform(-2, 2, 2), rng.uniform(-np.pi, np.pi)])
        b = np.array([*rng.uniform(-2, 2, 2), rng.uniform(-np.pi, np.pi)])
        s1, s2, s = space.allocState(), space.allocState(), space.allocState()
        for st_, q in ((s1, a), (s2, b)):
            st_.setXY(*q[:2])
            st_.setYaw(q[2])
        ab = unwrap_shortest(np.stack([a, b]))
        for t in (0.25, 0.5, 0.9):
            space.interpolate(s1, s2, t, s)
            q = ab[0] + t * (ab[1] - ab[0])
            assert np.allclose([s.getX(), s.getY()], q[:2])
            assert abs(np.angle(np.exp(1j * (s.getYaw() - q[2])))) < 1e-9


@pytest.mark.slow
def test_ompl_crossing_needed_and_bypass_fails(ompl, tilted):  # noqa: F811
    """A 1.3 m corridor with a low cylinder on its axis: OMPL's RRT-Connect finds the
    crossing (verified, and again at 10x sampling); with crossing disabled, the same
    search finds nothing."""
    sc, _ = tilted
    r = plan(sc, search="ompl-rrtconnect", time_budget=DETERMINISTIC)
    assert r.success and r.planner == "crossing" and r.search == "ompl-rrtconnect"
    assert r.crossed == ("low",) and r.verification.success and _rechecked(sc, r)
    b = plan(sc, baseline="se2", search="ompl-rrtconnect", iterations=600,
             time_budget=DETERMINISTIC)
    assert not b.success and b.status in ("budget_exhausted", "refuted")


def test_ompl_plans_are_reproducible(ompl, paper):  # noqa: F811
    """Same seed, same plan, whatever OMPL did in between (other seeds, other planners,
    random numbers drawn); another seed, another plan."""
    from ompl import util as ou
    first = plan(paper, search="ompl-rrtconnect", seed=3, time_budget=DETERMINISTIC)
    for _ in range(5):
        ou.RNG().uniform01()
    other = plan(paper, search="ompl-rrtconnect", seed=4, time_budget=DETERMINISTIC)
    again = plan(paper, search="ompl-rrtconnect", seed=3, time_budget=DETERMINISTIC)
    assert first.success and first.search == "ompl-rrtconnect"
    assert np.array_equal(first.robots, again.robots)
    assert not np.array_equal(first.robots, other.robots)


def test_ompl_rrtstar_paper_corridor(ompl, paper):  # noqa: F811
    r = plan(paper, search="ompl-rrtstar", time_budget=DETERMINISTIC)
    assert r.success and r.search == "ompl-rrtstar" and set(r.crossed) == {"1", "2"}
    assert r.verification.min_sheet_slack >= r.sheet_margin - 1e-9 and _rechecked(paper, r)


@pytest.mark.slow
def test_ompl_bypass_baseline_and_prm(ompl):
    """Where bypassing works, the SE(2) bypass baseline through OMPL bypasses (crosses
    nothing, verified); OMPL's PRM crosses there, shorter."""
    sc = corridor([Obstacle("low", 0.1, center=[3.0, 0.0], radius=0.1)], width=3.6)
    b = plan(sc, baseline="se2", search="ompl-rrtconnect", time_budget=DETERMINISTIC)
    assert b.success and b.planner == "se2-bypass" and b.search == "ompl-rrtconnect"
    assert b.crossed == () and _rechecked(sc, b)
    r = plan(sc, search="ompl-prm", time_budget=DETERMINISTIC)
    assert r.success and r.search == "ompl-prm" and _rechecked(sc, r)
    assert r.crossed == ("low",) and r.path_length < b.path_length


def test_cli_search_option(ompl, tmp_path, capsys):
    from taut.cli import main
    from ..test_plan import EXAMPLES
    out = tmp_path / "p.json"
    rc = main(["plan", str(EXAMPLES / "paper_corridor.yaml"), "--search", "ompl-rrtconnect",
               "--budget", "600", "--out", str(out)])
    data = json.loads(out.read_text())
    assert rc == 0 and data["search"] == "ompl-rrtconnect" and data["success"]
    capsys.readouterr()
    assert main(["plan", str(EXAMPLES / "paper_corridor.yaml"), "--search", "rrt"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("taut: error: --search: unknown search 'rrt'; choose one of")
