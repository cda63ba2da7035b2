"""Squeezed formations (taut.plan.formations._squeezed): narrower than the narrowest all-taut formation,
checked independently of the optimiser with forward kinematics and shapely."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from shapely.geometry import MultiPoint, Point

from taut.errors import InvalidInputError
from taut.plan import formation_library, generate_scenario, optimal_formation
from taut.plan.formations._squeezed import squeezed_formation
from taut.sheet import forward_kinematics

SHEET_MARGIN = 0.01
#: Suite (50, 2024) scenarios that pass beside an obstacle too tall to cross: index -> the
#: width (m) the passage needs, below the narrow all-taut formation's (0.858, 0.846, 0.776).
NEEDED = {3: 0.69, 20: 0.73, 39: 0.59}


@functools.lru_cache(maxsize=None)
def _scenario(index):
    """``generate_suite(50, 2024)[index]``, without generating the other 49."""
    return generate_scenario(2024 + index, 3 + index % 6)


def _team(index):
    return _scenario(index).team


@functools.lru_cache(maxsize=None)
def _narrow(index):
    """The library's narrow formation, computed alone (the whole library takes seconds
    for some scenarios, this a fraction of one); test_scenarios_are_the_suite_s checks
    that it is the library's."""
    sc = _scenario(index)
    return optimal_formation(sc.team, kind="narrow", width=sc.world.width,
                             sheet_margin=SHEET_MARGIN)


@functools.lru_cache(maxsize=None)
def _squeezed(index, width=None):
    return squeezed_formation(_team(index), sheet_margin=SHEET_MARGIN, width=width,
                              start=_narrow(index))


def _check(team, f, inset):
    """Every requirement, from forward kinematics and shapely alone; returns the inset and
    height margins (m)."""
    assert f.kind == "squeezed" and not f.robots.flags.writeable
    stable = forward_kinematics(team.carrier, f.robots).stable
    assert len(stable) == 1, [e.taut for e in stable]
    e = stable[0]
    np.testing.assert_allclose(e.object, [0.0, 0.0, f.object_height], rtol=0, atol=1e-6)
    assert e.height >= team.height_safety
    hull = MultiPoint([tuple(p) for p in f.robots[list(e.taut)]]).convex_hull
    centre = Point(*e.object[:2])
    assert hull.geom_type == "Polygon" and hull.contains(centre)
    assert hull.exterior.distance(centre) >= inset - 1e-9
    iu, ju = np.triu_indices(team.n, 1)
    dist = np.linalg.norm(f.robots[iu] - f.robots[ju], axis=1)
    sheet = np.linalg.norm(team.sheet.vertices[iu] - team.sheet.vertices[ju], axis=1)
    assert np.all(dist >= 2 * team.robot_radius - 1e-9)
    assert np.all(dist <= sheet - SHEET_MARGIN + 1e-9)
    weights = np.zeros(team.n)
    weights[list(e.taut)] = e.weights
    np.testing.assert_allclose(f.weights, weights, atol=1e-9)
    assert f.cost == pytest.approx(np.ptp(f.robots[:, 1]), abs=1e-12)
    assert f.reach == pytest.approx(np.linalg.norm(f.robots, axis=1).max() + team.clearance,
                                    abs=1e-9)
    return hull.exterior.distance(centre) - inset, e.height - team.height_safety


def test_scenarios_are_the_suite_s():
    team = _team(39)
    assert team.n == 6 and np.ptp(_narrow(39).robots[:, 1]) == pytest.approx(0.776, abs=1e-3)
    _, others, _ = formation_library(_scenario(39), sheet_margin=SHEET_MARGIN)
    narrow = next(f for f in others if f.kind == "narrow")
    np.testing.assert_array_equal(narrow.robots, _narrow(39).robots)


# Scenarios 3 and 20 (6 and 5 s of CPU) in the slow target; 39 keeps the rule covered.
@pytest.mark.parametrize("index", [pytest.param(3, marks=pytest.mark.slow),
                                   pytest.param(20, marks=pytest.mark.slow), 39])
def test_squeezed_fits_the_passage(index):
    """``width=`` stops at the first formation as narrow as the passage needs."""
    f = _squeezed(index, NEEDED[index])
    assert f is not None and f.cost <= NEEDED[index] + 1e-9
    assert np.ptp(_narrow(index).robots[:, 1]) > NEEDED[index]
    _check(_team(index), f, _team(index).robot_radius)


@pytest.mark.parametrize("index", [pytest.param(3, marks=pytest.mark.slow), 20,
                                   pytest.param(39, marks=pytest.mark.slow)])
def test_narrowest_squeezed_holds_the_object(index):
    team = _team(index)
    f = _squeezed(index)
    assert f is not None
    assert f.cost < NEEDED[index] - 0.1 < np.ptp(_narrow(index).robots[:, 1])
    assert f.cost <= _squeezed(index, NEEDED[index]).cost
    assert len(np.flatnonzero(f.weights)) < team.n          # some cables are slack
    _check(team, f, team.robot_radius)


def test_width_target_gives_a_more_robust_formation():
    team = _team(20)
    robust = min(_check(team, _squeezed(20, NEEDED[20]), team.robot_radius))
    narrowest = min(_check(team, _squeezed(20), team.robot_radius))
    assert robust > narrowest + 0.01                        # margins of centimetres


def test_default_start_and_determinism():
    team = _team(20)
    a = squeezed_formation(team, sheet_margin=SHEET_MARGIN, width=NEEDED[20])
    b = squeezed_formation(team, sheet_margin=SHEET_MARGIN, width=NEEDED[20])
    assert a is not None and b is not None and a.cost <= NEEDED[20] + 1e-9
    np.testing.assert_array_equal(a.robots, b.robots)
    _check(team, a, team.robot_radius)


def test_larger_inset_is_kept():
    f = squeezed_formation(_team(20), sheet_margin=SHEET_MARGIN, inset=0.15, width=0.6,
                           start=_narrow(20))
    assert f is not None
    _check(_team(20), f, 0.15)


def test_impossible_requirements_give_none():
    team = _team(20)
    assert squeezed_formation(team, inset=team.sheet.size) is None      # > half the sheet
    high = dataclasses.replace(team, height_safety=team.hold_height)    # no height left
    assert squeezed_formation(high) is None


def test_start_must_match_the_team():
    with pytest.raises(InvalidInputError):
        squeezed_formation(_team(20), start=_narrow(3))                 # six robots, not five


# Scenario 5 (3 s of CPU) in the slow target; 20 keeps the property covered.
@pytest.mark.parametrize("index", [pytest.param(5, marks=pytest.mark.slow), 20])
def test_squeezed_state_survives_position_error(index):
    """40 draws other than the design's (another seed): 5 mm of error per robot keeps a
    stable state above the height safety, inside its taut robots' hull, within 10 cm of
    the design (the design asks 5 cm on its own 12 draws)."""
    team = _team(index)
    f = squeezed_formation(team, sheet_margin=SHEET_MARGIN, width=NEEDED.get(index, 1.0))
    e0 = forward_kinematics(team.carrier, f.robots).stable[0]
    rng = np.random.default_rng(777)
    for _ in range(40):
        r = 0.005 * np.sqrt(rng.uniform(0, 1, team.n))
        a = rng.uniform(0, 2 * np.pi, team.n)
        P = f.robots + np.column_stack([r * np.cos(a), r * np.sin(a)])
        stable = forward_kinematics(team.carrier, P).stable
        assert stable
        e = min(stable, key=lambda e: np.linalg.norm(e.object - e0.object))
        assert np.linalg.norm(e.object - e0.object) <= 0.10
        assert e.height >= team.height_safety
        hull = MultiPoint([tuple(p) for p in P[list(e.taut)]]).convex_hull
        assert hull.contains(Point(*e.object[:2]))


def test_library_refuses_a_crossing_formation_that_loses_the_object():
    """Suite scenario 2042 (3 robots): lifting the object over the 0.178 m post needs the
    sheet nearly flat (every pair within 11 mm of its sheet distance); 5 mm of robot error
    then leaves no rest state at all in about one case in twenty (checked here on other
    draws), so the library keeps that formation out and says why."""
    from taut.plan.formations.library import _robust
    sc = generate_scenario(2042, 3)
    _, others, notes = formation_library(sc, sheet_margin=SHEET_MARGIN)
    assert all(f.object_height < 0.2 for f in others)
    assert any("'o2' (0.178 m tall) cannot be crossed" in n and "loses it" in n for n in notes)
    flat = optimal_formation(sc.team, kind="crossing", height=0.178, diameter=0.2,
                             width=sc.world.width, max_reach=0.49 * sc.world.width,
                             sheet_margin=SHEET_MARGIN)
    assert flat is not None and not _robust(sc.team, flat)
    rng = np.random.default_rng(99)
    lost = 0
    for _ in range(300):
        r = 0.005 * np.sqrt(rng.uniform(0, 1, 3))
        a = rng.uniform(0, 2 * np.pi, 3)
        P = flat.robots + np.column_stack([r * np.cos(a), r * np.sin(a)])
        lost += not forward_kinematics(sc.team.carrier, P).stable
    assert 0 < lost < 60
    assert _robust(sc.team, others[0])
