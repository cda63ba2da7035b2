"""The batching rule (issue 10): single in -> single out, batch in -> batch out.

Every public function of ``taut.cdpr`` that takes platform poses (or cable lengths, or
positions) is enumerated from ``taut.cdpr.__all__``; each is called on one pose and on a
batch of two poses whose first row is that pose. The single call must return the batch
call's first row with the leading axis dropped (``success`` a ``bool``, ``status`` a
``str``), so the rule cannot change a number. A public function that takes poses but is
missing from the table below fails ``test_every_pose_function_is_covered``. The sheet
keeps one function per form (``forward_kinematics`` / ``forward_kinematics_batch``,
``check_formation`` / ``check_formations``); the same agreement is checked there.
"""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest

import taut.cdpr as cdpr
import taut.sheet as sheet_api
from taut.errors import TautError
from taut.io.cdpr_model import load_cdpr_model

POSES = np.array([[0.3, 0.1, 1.0, 0.02, -0.03, 0.05], [-0.5, 0.0, 1.4, 0.0, 0.0, 0.0]])

#: name -> (callable(robot, one_or_batch) , robot preset). The callable receives the pose
#: argument in either form; everything else is fixed.
CASES = {
    "cable_state": (lambda r, p: cdpr.cable_state(r, p), "fastkit"),
    "wrench_matrix": (lambda r, p: cdpr.wrench_matrix(r, p), "fastkit"),
    "parallel_jacobian": (lambda r, p: cdpr.parallel_jacobian(r, p), "fastkit"),
    "distribute_tensions": (lambda r, p: cdpr.distribute_tensions(r, p, "qp_min_norm"),
                            "fastkit"),
    "tipping_moments": (lambda r, p: cdpr.tipping_moments(r, p, r.t_min), "fastkit"),
    "wrench_feasible": (lambda r, p: cdpr.wrench_feasible(r, p), "fastkit"),
    "available_wrench_set": (lambda r, p: cdpr.available_wrench_set(r, p), "fastkit"),
    "axis_capacities": (lambda r, p: cdpr.axis_capacities(r, p), "fastkit"),
    "capacity_margin": (lambda r, p: cdpr.capacity_margin(r, p), "fastkit"),
    "wrench_closure": (lambda r, p: cdpr.wrench_closure(r, p), "fastkit_fc"),
    "cable_interference": (lambda r, p: cdpr.cable_interference(r, p), "fastkit"),
    "platform_inside_exits": (lambda r, p: cdpr.platform_inside_exits(r, p), "fastkit"),
    "first_order_model": (lambda r, p: cdpr.first_order_model(r, p), "fastkit"),
    "available_twist_set": (lambda r, p: cdpr.available_twist_set(r, p), "fastkit"),
    "twist_capacities": (lambda r, p: cdpr.twist_capacities(r, p), "fastkit"),
    "upward_force_bound": (lambda r, p: cdpr.upward_force_bound(r, np.asarray(p)[..., :3]),
                           "fastkit"),
    "cable_forward_kinematics": (
        lambda r, p: cdpr.cable_forward_kinematics(r, cdpr.cable_state(r, p).lengths),
        "fastkit"),
}
#: Pose-taking functions outside the rule, with the reason.
EXEMPT = {
    "as_poses": "the validator: always returns the (B, 6) working form",
    "resolve_redundancy": "one pose and one twist only (no batched form)",
    "grid_points": "builds a grid, takes a box",
    "wrench_feasible_workspace": "a workspace is a set of points: always a batch",
    "reference_from_samples": "a trajectory: always a time series",
    "place_bases": "takes base poses, returns a robot",
    "evaluate_deployment": "scores one placement over a set of sample points",
    "plan_base_drive": "one platform pose held along a base drive (a time series of bases)",
    "to_robot_frame": "one pose of the coupled bases; its points broadcast over any leading axes",
    "to_world_frame": "one pose of the coupled bases; its points broadcast over any leading axes",
}


def _pose_functions():
    for name in cdpr.__all__:
        obj = getattr(cdpr, name)
        if inspect.isfunction(obj):
            params = inspect.signature(obj).parameters
            if {"poses", "pose", "points", "lengths"} & set(params):
                yield name


def test_every_pose_function_is_covered():
    missing = set(_pose_functions()) - set(CASES) - set(EXEMPT)
    assert not missing, f"add these to CASES or EXEMPT: {sorted(missing)}"


def _fields(res):
    if dataclasses.is_dataclass(res):
        return {f.name: getattr(res, f.name) for f in dataclasses.fields(res)}
    return {"value": res}


def _assert_first_row(single, batch, name, path=""):
    """``single`` is ``batch`` without its leading axis (recursively over dataclasses)."""
    if dataclasses.is_dataclass(batch) and not isinstance(batch, type):
        for key, b in _fields(batch).items():
            _assert_first_row(getattr(single, key), b, name, f"{path}.{key}")
        return
    if isinstance(batch, np.ndarray) and batch.ndim and batch.shape[0] == 2:
        want = batch[0]
        if want.ndim == 0:
            if want.dtype == bool:
                assert type(single) is bool, f"{name}{path}: {type(single)} not bool"
            elif want.dtype.kind in "US":
                assert type(single) is str, f"{name}{path}: {type(single)} not str"
        else:
            assert isinstance(single, np.ndarray) and single.shape == want.shape, \
                f"{name}{path}: {np.shape(single)} != {want.shape}"
        np.testing.assert_array_equal(np.asarray(single), want, err_msg=f"{name}{path}")
    elif isinstance(batch, np.ndarray):
        np.testing.assert_array_equal(single, batch, err_msg=f"{name}{path}")


@pytest.fixture(scope="module")
def robots():
    return {k: load_cdpr_model(k) for k in ("fastkit", "fastkit_fc")}


@pytest.mark.parametrize("name", sorted(CASES))
def test_single_in_single_out_batch_in_batch_out(name, robots):
    fn, preset = CASES[name]
    robot = robots[preset]
    batch = fn(robot, POSES)
    single = fn(robot, POSES[0])
    leading = [v.shape[0] for v in _fields(batch).values()
               if isinstance(v, np.ndarray) and v.ndim and v.shape[0] == 2]
    assert leading, f"{name}: the batch result has no leading axis of length 2"
    _assert_first_row(single, batch, name)
    one = fn(robot, POSES[:1])                        # a batch of one stays a batch
    for key, v in _fields(one).items():
        b = _fields(batch)[key]
        if isinstance(b, np.ndarray) and b.ndim and b.shape[0] == 2:
            assert np.shape(v)[:1] == (1,), f"{name}.{key}: a (1, 6) batch lost its axis"


def test_polytope_methods_follow_the_rule(robots):
    robot = robots["fastkit"]
    both = np.array([[0.0, 0.0, 0.6, 0, 0, 0], POSES[1]])
    aws1 = cdpr.available_wrench_set(robot, both[0])
    aws2 = cdpr.available_wrench_set(robot, both)
    w = -aws1.gravity_wrench
    assert aws1.contains(w) is True and aws2.contains(w).shape == (2,)   # holds its weight
    assert aws1.contains(w) == aws2.contains(w)[0]
    assert float(aws1.margin(w)) == aws2.margin(w)[0]
    np.testing.assert_array_equal(aws1.facets()[1], aws2.facets(0)[1])
    assert aws1.support(np.eye(6)[2]) == pytest.approx(aws2.support(np.eye(6)[2], 0))


def test_sheet_single_and_batch_forms_agree():
    from pathlib import Path

    from taut.io.sheet_scenario import load_sheet_scenario
    sc = load_sheet_scenario(Path(__file__).parent.parent / "examples/sheet/example1.yaml")
    team, R = sc.team, np.asarray(sc.formation, dtype=float)
    s = team.sheet
    one = sheet_api.forward_kinematics(team, R)
    many = sheet_api.forward_kinematics_batch(team, np.stack([R, R * 1.01]))
    assert many.count.shape == (2,)
    first = many.result(0)
    assert [e.taut for e in first.equilibria] == [e.taut for e in one.equilibria]
    np.testing.assert_allclose([e.object for e in first.equilibria],
                               [e.object for e in one.equilibria], atol=1e-9)
    assert sheet_api.check_formation(s, R).shape == R.shape
    assert sheet_api.check_formations(s, R[None]).shape == (1,) + R.shape
    with pytest.raises(TautError):
        sheet_api.forward_kinematics(team, np.stack([R, R]))    # a batch to the single form
    with pytest.raises(TautError):
        sheet_api.forward_kinematics_batch(team, R)             # one formation to the batch
