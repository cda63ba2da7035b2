"""Where to stand (issue 30 part 3): sites whose wrench-feasible workspace (tipping and
sliding) holds the picks and places done there, footprints clear; unserved tasks reported."""

from pathlib import Path

import numpy as np
import pytest
import shapely

from taut.cdpr import (Shelf, Task, Warehouse, choose_sites, coupled_footprint,
                       to_robot_frame, wrench_feasible)
from taut.cdpr.mission._cover import with_payload
from taut.errors import TautError
from taut.io import load_warehouse

ROOT = Path(__file__).parents[3]


@pytest.fixture(scope="module")
def two_racks(fastkit):
    """Two racks 17 m apart: no single site reaches both; box3 sits 2 m up."""
    shelves = (Shelf("A", [[3, 9], [8, 9], [8, 10], [3, 10]]),
               Shelf("B", [[20, 9], [25, 9], [25, 10], [20, 10]]))
    tasks = (Task("box1", (5.0, 9.0, 0.6), (6.5, 9.0, 1.0), 4.0),
             Task("box2", (22.0, 9.0, 0.6), (23.0, 9.0, 1.2), 3.0),
             Task("box3", (5.5, 9.0, 2.0), (6.0, 9.0, 1.0), 5.0))
    return Warehouse(fastkit, [[0, 0], [30, 0], [30, 12], [0, 12]], shelves,
                     (5.0, 3.0, 0.0), tasks)


@pytest.fixture(scope="module")
def result(two_racks):
    return choose_sites(two_racks, step=0.5)


def test_two_sites_and_the_unreachable_box(result):
    assert result.status == "unreachable" and not result.success
    assert len(result.sites) == 2
    assert sorted(n for s in result.sites for n in s.task_names) == ["box1", "box2"]
    assert [u.name for u in result.unserved] == ["box3"]
    assert "out of reach" in result.unserved[0].reason and "5 kg" in result.unserved[0].reason


def test_each_site_serves_its_tasks(two_racks, result):
    """Independent re-check of every site: gripper reach, wrench feasibility with tipping
    and sliding empty and loaded, the deployed footprint clear of walls and shelves."""
    wh = two_racks
    tasks = {t.name: t for t in wh.tasks}
    for site in result.sites:
        r = site.robot
        assert site.stabilisers_deployed and all(b.stabilisers_deployed for b in r.bases
                                                 if b.mobile)
        assert all(b.friction == wh.friction for b in r.bases if b.mobile)
        for name, p, q in zip(site.task_names, site.picks, site.places):
            t = tasks[name]
            for world, target in ((t.pick, p), (t.place, q)):
                local = to_robot_frame(site.pose, world)
                assert abs(local[1]) <= wh.gripper_reach + 1e-9
                assert np.allclose(target, [local[0], 0.0, local[2]])
                for m in (0.0, t.mass):
                    assert wrench_feasible(with_payload(r, m), [*target, 0, 0, 0],
                                           tipping=True, sliding=True)
        assert site.margin >= 0
        body = coupled_footprint(r, deployed=True)
        c, s = np.cos(site.pose[2]), np.sin(site.pose[2])
        fp = shapely.Polygon(body @ np.array([[c, s], [-s, c]]) + site.pose[:2])
        assert wh.floor.covers(fp) and wh.floor.exterior.distance(fp) >= wh.clearance - 1e-9
        for sh in wh.shelves:
            assert sh.footprint.distance(fp) >= wh.clearance - 1e-9
        # the bases at the site are the model's placement moved with the coupled pose
        assert site.base_poses.shape == (2, 3)


def test_the_check_can_fail(two_racks, result):
    """The same targets seen from the other site are out of reach or infeasible."""
    a, b = result.sites
    t = {t.name: t for t in two_racks.tasks}[a.task_names[0]]
    local = to_robot_frame(b.pose, t.pick)
    lo, hi = b.robot.bounds
    target = np.array([local[0], 0.0, local[2]])
    assert (abs(local[1]) > two_racks.gripper_reach or np.any(target < lo) or
            np.any(target > hi) or not wrench_feasible(with_payload(b.robot, t.mass),
                                                       [*target, 0, 0, 0]))


def test_bad_input_is_named(two_racks):
    with pytest.raises(TautError) as exc:
        choose_sites(two_racks, step=0.0)
    assert exc.value.field == "step"
    with pytest.raises(TautError) as exc:
        choose_sites("warehouse.yaml")
    assert exc.value.field == "warehouse"


@pytest.mark.slow
def test_example_warehouse_needs_two_sites():
    res = choose_sites(load_warehouse(ROOT / "examples" / "cdpr" / "warehouse.yaml"))
    assert len(res.sites) == 2 and [u.name for u in res.unserved] == ["box8"]
    assert sorted(n for s in res.sites for n in s.task_names) == [f"box{i}" for i in
                                                                   range(1, 8)]
