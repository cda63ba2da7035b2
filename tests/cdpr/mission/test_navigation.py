"""Navigation mode (issue 30 part 2): the coupled bases' route, verified at every instant
independently of the search; refusals with what they prove."""

import numpy as np
import pytest
import shapely

from taut.cdpr import Shelf, Task, Warehouse, plan_navigation
from taut.errors import TautError


def _warehouse(fastkit, shelves, floor=((0, 0), (20, 0), (20, 12), (0, 12)), **kw):
    return Warehouse(fastkit, floor, tuple(Shelf(n, f) for n, f in shelves),
                     (4.5, 2.0, 0.0), (Task("b", (8, 5, 1), (8, 5, 1), 1.0),), **kw)


@pytest.fixture(scope="module")
def small(fastkit):
    return _warehouse(fastkit, [("S", [[8, 5], [12, 5], [12, 7], [8, 7]])])


@pytest.fixture(scope="module")
def route(small):
    return plan_navigation(small, small.start, (13.0, 9.5, 0.3))


def _footprints(wh, poses):
    body = wh.body
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    x = c[:, None] * body[None, :, 0] - s[:, None] * body[None, :, 1] + poses[:, :1]
    y = s[:, None] * body[None, :, 0] + c[:, None] * body[None, :, 1] + poses[:, 1:2]
    return shapely.polygons(np.stack([x, y], axis=-1))


def test_route_keeps_clearance_at_every_instant(small, route):
    assert route.success and route.status == "ok", route.message
    assert np.allclose(route.poses[0], small.start)
    assert np.allclose(route.poses[-1, :2], (13.0, 9.5)) and np.isclose(
        np.angle(np.exp(1j * (route.poses[-1, 2] - 0.3))), 0.0)
    # Independent re-check: between two samples the motion runs along one straight SE(2)
    # segment (a corner is always a sample), so dense interpolation stays on the path.
    u = np.linspace(0, 1, 9)[None, :, None]
    dense = (route.poses[:-1, None] + u * np.diff(route.poses, axis=0)[:, None]).reshape(-1, 3)
    fp = _footprints(small, dense)
    assert shapely.covers(small.floor, fp).all()
    gap = shapely.distance(small.floor.exterior, fp)
    for sh in small.shelves:
        gap = np.minimum(gap, shapely.distance(sh.footprint, fp))
    assert gap.min() >= small.clearance - 1e-6
    assert route.min_clearance >= small.clearance - 1e-6


def test_route_respects_speed_limits(small, route):
    dt = np.diff(route.times)
    v = np.linalg.norm(np.diff(route.poses[:, :2], axis=0), axis=1) / dt
    w = np.abs(np.diff(route.poses[:, 2])) / dt
    assert v.max() <= small.max_speed * (1 + 1e-6)
    assert w.max() <= small.max_turn_rate * (1 + 1e-6)
    assert np.isclose(route.times[-1], route.duration)
    # rest to rest: starts and stops still
    assert v[0] * dt[0] <= 0.5 * small.max_accel * dt[0] ** 2 * (1 + 1e-6) + 1e-12


def test_a_broken_route_fails_the_check(small, route):
    """The re-check above can fail: the same route shifted into the shelf does."""
    moved = route.poses + [0.0, -2.0, 0.0]
    fp = _footprints(small, moved)
    assert shapely.intersects(small.shelves[0].footprint, fp).any() or \
        not shapely.covers(small.floor, fp).all()


def test_goal_colliding_is_refused_with_a_proof(small):
    r = plan_navigation(small, small.start, (10.0, 7.2, 0.0))
    assert not r.success and r.status == "unreachable"
    c = r.certificate
    assert c.kind == "goal_collides" and c.proven and "S" in c.blockers
    assert "proven" in r.message and r.times.shape == (0,)


def test_disconnected_floor_is_refused_with_a_certificate(fastkit):
    wh = _warehouse(fastkit, [("wall", [[9, 0], [10, 0], [10, 10], [9, 10]])],
                    floor=((0, 0), (20, 0), (20, 10), (0, 10)))
    r = plan_navigation(wh, wh.start, (15.0, 5.0, 0.0))
    assert not r.success and r.status == "no_route"
    c = r.certificate
    assert c.kind == "disconnected" and c.proven and c.expanded > 0
    assert "resolution" in c.message and "not ruled out" in c.message


def test_budget_is_a_diagnosis_not_a_proof(small):
    r = plan_navigation(small, small.start, (13.0, 9.5, 0.3), expansions=5)
    assert r.status == "budget_exhausted" and not r.certificate.proven


@pytest.mark.parametrize("kw,field", [({"max_speed": -1.0}, "max_speed"),
                                      ({"max_accel": float("nan")}, "max_accel"),
                                      ({"spacing": 0.0}, "spacing"),
                                      ({"expansions": 1.5}, "expansions")])
def test_bad_options_are_named(small, kw, field):
    with pytest.raises(TautError) as exc:
        plan_navigation(small, small.start, (13.0, 9.5, 0.0), **kw)
    assert exc.value.field == field


def test_bad_poses_are_named(small):
    with pytest.raises(TautError) as exc:
        plan_navigation(small, (1.0, 2.0), (13.0, 9.5, 0.0))
    assert exc.value.field == "start"


@pytest.mark.slow
def test_example_routes_between_the_sites():
    from pathlib import Path
    from taut.cdpr import choose_sites
    from taut.io import load_warehouse
    wh = load_warehouse(Path(__file__).parents[3] / "examples" / "cdpr" / "warehouse.yaml")
    a, b = (s.pose for s in choose_sites(wh).sites)
    for start, goal in ((wh.start, a), (a, b), (b, wh.start)):
        r = plan_navigation(wh, start, goal)
        assert r.success, r.message
        assert r.min_clearance >= wh.clearance - 1e-9
        assert np.allclose(r.poses[0], start)
