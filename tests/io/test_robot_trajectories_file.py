"""The JSON form of executed robot trajectories (``taut plan --trajectories t.json``) read
with a strict schema (issue 24, "one safe loader for every file"): an unknown key, a
boolean, ``null`` or a string where a number belongs is refused naming the key, and what
taut writes (a successful run, a failed one with NaN durations, unset limits) reads back
exactly."""

from typing import Any, get_args

import numpy as np
import pytest

from taut.errors import InvalidTrajectoryError, ScenarioError
from taut.io.robot_trajectories import (_TrajectoriesFile, load_robot_trajectories,
                                        robot_trajectories_from_mapping,
                                        robot_trajectories_to_dict, save_robot_trajectories)
from taut.io.serialize import to_json
from taut.plan.execution._drives import DRIVES
from taut.plan.execution.trajectories import RobotTrajectories


def _executed(T: int = 4, n: int = 3, success: bool = True) -> RobotTrajectories:
    rng = np.random.default_rng(7)
    times = np.cumsum(rng.random(T)) - 0.1 if T else np.zeros(0)
    return RobotTrajectories(
        success, "ok" if success else "no_route", "a message", times,
        rng.normal(size=(T, n, 3)), rng.normal(size=(T, 3)), "differential",
        float(times[-1]) if T else float("nan"), 2.5, turns=1, peak_speed=0.2,
        limits=(0.2, 0.5, 1.0, np.inf))


def _data() -> dict[str, Any]:
    """A complete file as taut writes it, parsed (the unset limit is ``null``)."""
    import json
    return json.loads(to_json(robot_trajectories_to_dict(_executed()), indent=None))


@pytest.mark.parametrize("suffix", [".json", ".csv"])
@pytest.mark.parametrize("success, T", [(True, 4), (False, 0)])
def test_a_file_taut_writes_reads_back_exactly(tmp_path, success, T, suffix):
    """Both forms; a failed plan's JSON has no sample to count its robots by, its CSV
    header does."""
    tr = _executed(T, success=success)
    path = tmp_path / f"t{suffix}"
    save_robot_trajectories(path, tr)
    back = load_robot_trajectories(path)
    np.testing.assert_array_equal(back.times, tr.times)
    np.testing.assert_array_equal(back.object, tr.object)
    assert back.poses.shape == ((T, 3, 3) if T or suffix == ".csv" else (0, 0, 3))
    if T:
        np.testing.assert_array_equal(back.poses, tr.poses)


def test_the_drive_choices_are_the_planners():
    assert get_args(_TrajectoriesFile.model_fields["drive"].annotation) == DRIVES


def _set(data: dict[str, Any], path: tuple, value: Any) -> dict[str, Any]:
    node: Any = data
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return data


@pytest.mark.parametrize("path, value, field, problem", [
    (("zz_not_a_key",), 1, "zz_not_a_key", "unknown key"),
    (("limits", "zz"), 1, "limits.zz", "unknown key"),
    (("times_s", 1), True, "times_s[1]", "must be a number, got a boolean"),
    (("poses_m_rad", 2, 1, 0), False, "poses_m_rad[2][1][0]", "must be a number, got a boolean"),
    (("object_m", 3, 2), None, "object_m[3][2]", "valid number"),
    (("times_s", 0), None, "times_s[0]", "valid number"),
    (("poses_m_rad", 0, 0, 2), "1.5", "poses_m_rad[0][0][2]", "valid number"),
    (("duration_s",), "3", "duration_s", "valid number"),
    (("turns_in_place",), 1.0, "turns_in_place", "valid integer"),
    (("peaks", "speed_mps"), True, "peaks.speed_mps", "must be a number, got a boolean"),
    (("drive",), "tank", "drive", "holonomic"),
    (("status",), "fine", "status", "ok"),
])
def test_a_bad_value_is_refused_naming_its_key(path, value, field, problem):
    with pytest.raises(InvalidTrajectoryError) as err:
        robot_trajectories_from_mapping(_set(_data(), path, value))
    assert err.value.field == field, str(err.value)
    assert problem in err.value.problem, str(err.value)


def test_a_missing_key_or_sample_count_mismatch_is_refused_naming_it():
    data = _data()
    del data["object_m"]
    with pytest.raises(InvalidTrajectoryError) as err:
        robot_trajectories_from_mapping(data)
    assert err.value.field == "object_m" and "missing" in err.value.problem
    data = _data()
    data["object_m"].pop()
    with pytest.raises(InvalidTrajectoryError) as err:
        robot_trajectories_from_mapping(data)
    assert err.value.field == "object_m" and "3 samples; times_s has 4" in err.value.problem
    data = _data()
    data["poses_m_rad"][2].pop()
    with pytest.raises(InvalidTrajectoryError) as err:
        robot_trajectories_from_mapping(data)
    assert err.value.field == "poses_m_rad[2]" and "2 robots" in err.value.problem


def _nan_file() -> str:
    """A complete file whose first time is the bare ``NaN`` token Python's json accepts."""
    data = _data()
    data["times_s"][0] = 12345.5
    return to_json(data, indent=None).replace("12345.5", "NaN")


@pytest.mark.parametrize("text, error, field", [
    (_nan_file, InvalidTrajectoryError, "times_s[0]"),
    (lambda: '{"a": 1, "a": 2}', ScenarioError, None),        # a key given twice
    (lambda: "[1, 2]", ScenarioError, None),                  # not a mapping
])
def test_files_that_are_not_trajectories_are_one_error(tmp_path, text, error, field):
    path = tmp_path / "t.json"
    path.write_text(text())
    with pytest.raises(error) as err:
        load_robot_trajectories(path)
    if field is not None:
        assert err.value.field == field, str(err.value)


@pytest.mark.parametrize("cell, problem", [
    ("nan", "row 3: a cell is NaN or infinite"),
    ("-inf", "row 3: a cell is NaN or infinite"),
    ("1e309", "row 3: a cell is NaN or infinite"),          # overflows to inf
    ("one", "row 3: a cell is not a number"),
    (None, "row 3: 12 cells; the header has 13"),           # a cell missing
])
def test_the_csv_form_refuses_a_bad_cell_naming_its_row(tmp_path, cell, problem):
    path = tmp_path / "t.csv"
    save_robot_trajectories(path, _executed())
    lines = path.read_text().splitlines()
    cells = lines[2].split(",")
    if cell is None:
        cells.pop()
    else:
        cells[5] = cell
    lines[2] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InvalidTrajectoryError) as err:
        load_robot_trajectories(path)
    assert problem in str(err.value) and "t.csv" in str(err.value)
