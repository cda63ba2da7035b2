"""The warehouse file and model (issue 30 part 1): the example loads; every bad field is a
TautError naming it; frames round-trip."""

import copy
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.cdpr import (Shelf, Task, Warehouse, coupled_footprint, to_robot_frame,
                       to_world_frame)
from taut.errors import TautError
from taut.io import load_warehouse, read_mapping

ROOT = Path(__file__).parents[3]
EXAMPLE = ROOT / "examples" / "cdpr" / "warehouse.yaml"


@pytest.fixture(scope="module")
def data():
    return read_mapping(EXAMPLE)


def test_example_loads(data):
    wh = load_warehouse(EXAMPLE)
    assert wh.robot.name == "fastkit"
    assert [s.name for s in wh.shelves] == ["A", "K", "B"]
    assert len(wh.tasks) == 8 and wh.tasks[0].pick.tolist() == [8.6, 11.0, 0.6]
    assert wh.gripper_reach == 1.0 and wh.friction == 0.5
    # the same from the parsed mapping
    assert load_warehouse(data).tasks[-1].name == "box8"


BAD = [
    (("floor",), [[0, 0], [1, 1], [0, 1], [1, 0]], "floor"),            # self-intersecting
    (("floor",), [[0, 0], [1, 0]], "floor"),
    (("start",), [1.0, 2.0], "start"),
    (("start",), [1.0, "x", 0.0], "start"),
    (("robot",), "nonexistent_preset", "robot"),
    (("robot",), "missing/model.yaml", "robot"),
    (("shelves", 0, "footprint"), [[2, 10], [40, 10], [40, 11], [2, 11]], "shelves[0].footprint"),
    (("shelves", 1, "name"), "A", "shelves[1].name"),
    (("shelves", 0, "footprint"), [[7, 6.9], [13, 6.9], [13, 9.1], [7, 9.1]],
     "shelves[1].footprint"),                                  # K (the later) overlaps A
    (("shelves", 0, "height_m"), 0.0, "shelves[0].height_m"),
    (("shelves", 2, "height_m"), "tall", "shelves"),
    (("tasks", 2, "pick"), [1.0, 2.0], "tasks[2].pick"),
    (("tasks", 2, "place"), [1.0, 2.0, -0.5], "tasks[2].place"),
    (("tasks", 3, "mass"), -1.0, "tasks[3].mass"),
    (("tasks", 3, "mass"), float("nan"), "tasks[3].mass"),
    (("tasks", 1, "name"), "box1", "tasks[1].name"),
    (("tasks",), [], "tasks"),
    (("gripper_reach_m",), 0.0, "gripper_reach_m"),
    (("clearance_m",), -0.1, "clearance_m"),
    (("max_speed_m_s",), -1.0, "max_speed_m_s"),
    (("friction",), -0.5, "friction"),
    (("unknown_key",), 1, "unknown_key"),
]


@pytest.mark.parametrize("path,value,field", BAD, ids=[b[2] for b in BAD])
def test_bad_field_is_named(data, path, value, field):
    d = copy.deepcopy(data)
    target = d
    for step in path[:-1]:
        target = target[step]
    target[path[-1]] = value
    with pytest.raises(TautError) as exc:
        load_warehouse(d)
    assert exc.value.field.startswith(field), (exc.value.field, exc.value.problem)


def test_missing_key_is_named(data):
    d = copy.deepcopy(data)
    del d["start"]
    with pytest.raises(TautError, match="start"):
        load_warehouse(d)


def test_robot_model_path_is_relative_to_the_file(tmp_path, data):
    model = ROOT / "src" / "taut" / "data" / "fastkit.yaml"
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "mine.yaml").write_text(model.read_text())
    d = dict(data, robot="models/mine.yaml")
    import yaml
    (tmp_path / "wh.yaml").write_text(yaml.safe_dump(d))
    assert load_warehouse(tmp_path / "wh.yaml").robot.name == "fastkit"


def test_models_validate_directly(data):
    wh = load_warehouse(data)
    with pytest.raises(TautError, match="robot"):
        Warehouse("fastkit", wh.floor, wh.shelves, wh.start, wh.tasks)
    with pytest.raises(TautError, match="mass"):
        Task("b", [0, 0, 1], [1, 1, 1], 0.0)
    with pytest.raises(TautError, match="footprint"):
        Shelf("s", [[0, 0], [1, 0]])


def test_coupled_footprint_contains_both_bases(fastkit):
    body = coupled_footprint(fastkit)
    import shapely
    hull = shapely.Polygon(body)
    for b in fastkit.bases:
        assert hull.covers(shapely.Polygon(b.support_world()[:, :2]))
    assert hull.covers(shapely.Polygon(coupled_footprint(fastkit, deployed=True))) is False


@settings(max_examples=40, deadline=None)
@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-7, 7),
       st.lists(st.floats(-20, 20), min_size=3, max_size=3))
def test_frames_round_trip_and_keep_distances(x, y, yaw, p):
    pose = (x, y, yaw)
    q = to_robot_frame(pose, p)
    assert np.allclose(to_world_frame(pose, q), p, atol=1e-9)
    assert q[2] == p[2]
    assert np.isclose(np.linalg.norm(q[:2]), np.hypot(p[0] - x, p[1] - y), atol=1e-9)
