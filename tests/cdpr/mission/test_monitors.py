"""Collision and stabiliser monitors of the mission (taut.cdpr.mission._monitors and the
static phases of ._execute): cables against solid shelves cross-checked by brute force,
the stabiliser sequence, the navigation and deploy monitors."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings, strategies as st

from taut.cdpr import NavigationResult, Shelf, with_box, with_friction, with_stabilisers
from taut.cdpr.mission import _execute
from taut.cdpr.mission._execute import navigate_run, switch_stabilisers
from taut.cdpr.mission._monitors import (_shelf_gap, cable_clearance, stabiliser_sequence)
from taut.io import load_warehouse

EXAMPLE = Path(__file__).parents[3] / "examples" / "cdpr" / "warehouse.yaml"

SHELF = shapely.Polygon([(0, 0), (2, 0), (2, 1), (0, 1)])


def _brute(a, b, height, n=4001):
    """Gap from many points of the segment to the box (exact point-to-box distance)."""
    s = np.linspace(0, 1, n)[:, None]
    p = a + s * (b - a)
    dx = np.maximum(np.maximum(-p[:, 0], p[:, 0] - 2), 0)
    dy = np.maximum(np.maximum(-p[:, 1], p[:, 1] - 1), 0)
    dz = np.maximum(np.maximum(-p[:, 2], p[:, 2] - height), 0)
    return np.sqrt(dx ** 2 + dy ** 2 + dz ** 2).min()


coord = st.floats(-3, 5)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.tuples(coord, coord, st.floats(0, 4)), st.tuples(coord, coord, st.floats(0, 4)),
       st.floats(0.5, 3))
def test_cable_gap_matches_brute_force(a, b, height):
    a, b = np.array(a), np.array(b)
    gap = _shelf_gap(SHELF, height, a[None], b[None])[0]
    ref = _brute(a, b, height)
    if ref < 1e-9:
        assert gap == pytest.approx(0.0, abs=1e-9)           # touching is caught exactly
    else:
        length = np.linalg.norm(b - a)
        # never below the true gap, which the brute force overestimates by at most half
        # its sample spacing
        assert gap >= ref - length / 8000 - 1e-9
        assert gap <= ref + length / 23 + 1e-6                 # half a sample spacing at most


def test_a_cable_through_a_shelf_and_one_over_it():
    gap = _shelf_gap(SHELF, 1.0, np.array([[-1.0, 0.5, 0.5], [-1.0, 0.5, 1.5]]),
                     np.array([[3.0, 0.5, 0.5], [3.0, 0.5, 1.5]]))
    assert gap[0] == 0.0 and gap[1] == pytest.approx(0.5)


def test_stabiliser_sequence_switches_base_by_base():
    robot = load_warehouse(EXAMPLE).robot
    down = stabiliser_sequence(robot, True)
    assert down == [(False, False), (True, False), (True, True)]
    assert stabiliser_sequence(robot, False) == [(True, True), (True, False), (False, False)]


@pytest.fixture(scope="module")
def warehouse():
    return load_warehouse(EXAMPLE)


def test_shelf_height_is_validated_and_seen_by_the_cables(warehouse):
    with pytest.raises(Exception) as exc:
        Shelf("X", [[0, 0], [1, 0], [1, 1]], height=-1.0)
    assert "height" in exc.value.field
    robot = with_box(with_stabilisers(with_friction(warehouse.robot, warehouse.friction)), 0)
    pose, p6 = np.array([10.0, 10.05, 0.0]), np.array([[0.0, 0.0, 1.0, 0, 0, 0]])
    gap = cable_clearance(warehouse, robot, pose, p6)
    assert gap > 0
    # the same site with the rack moved under the cable plane: the cables hit it
    low = Shelf("Z", [[8.0, 9.9], [12.0, 9.9], [12.0, 10.2], [8.0, 10.2]], height=1.5)
    assert cable_clearance(replace(warehouse, shelves=(low,)), robot, pose, p6) == 0.0


def test_deploy_is_monitored_in_every_state(warehouse):
    robot = with_box(with_stabilisers(with_friction(warehouse.robot, warehouse.friction)), 0)
    run = switch_stabilisers(robot, True, np.array([0.0, 0.0, 0.5]), 3.0, warehouse,
                             np.array([10.0, 10.05, 0.0]))
    assert run.success and run.duration == 3.0 and len(run.times) == 4
    # the tipping margin is the least over the states: the all-up one is the worst
    up = switch_stabilisers(with_stabilisers(robot, deployed=False), True,
                            np.array([0.0, 0.0, 0.5]), 3.0, warehouse,
                            np.array([10.0, 10.05, 0.0]))
    assert run.min_tipping_margin == pytest.approx(up.min_tipping_margin)


def test_navigation_carries_the_inertial_load(warehouse, monkeypatch):
    robot = with_box(with_stabilisers(with_friction(warehouse.robot, warehouse.friction),
                                      deployed=False), 0)
    t = np.linspace(0.0, 4.0, 41)
    x = np.where(t < 2, 0.125 * t ** 2, 1.0 - 0.125 * (4 - t) ** 2)    # 0.25 m/s^2
    poses = np.column_stack([4.5 + x, np.full_like(t, 2.0), np.zeros_like(t)])
    nav = NavigationResult(True, "ok", "", t, poses, 4.0)
    run = navigate_run(warehouse, robot, np.array([0.0, 0.0, 0.5]), nav)
    still = navigate_run(warehouse, robot, np.array([0.0, 0.0, 0.5]),
                         NavigationResult(True, "ok", "", t, poses[:1].repeat(41, 0), 4.0))
    assert run.success and run.min_footprint_clearance > warehouse.clearance
    assert run.min_tension_margin < still.min_tension_margin      # the load shows
    # the bases' own d'Alembert force (45 kg at 0.6 m, 0.25 m/s^2: 6.75 N m) costs tipping
    # margin beyond what the platform's load alone costs
    monkeypatch.setattr(_execute, "with_base_acceleration", lambda r, a: r)
    old = navigate_run(warehouse, robot, np.array([0.0, 0.0, 0.5]), nav)
    assert old.min_tipping_margin - run.min_tipping_margin == pytest.approx(6.75, rel=0.1)
    assert len(run.times) == len(t)
