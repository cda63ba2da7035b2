"""The conventions every cable-robot analysis follows: one result convention (success,
status, message; no older names), one default for `tipping`, one name for the extra
external wrench, one public import path, and the cable_state pose-index regression."""

import dataclasses
import inspect

import numpy as np
import pytest

import taut.cdpr as cdpr
from taut._outcome import STATUSES
from taut.cdpr import (DeploymentResult, RedundancyResult, TensionResult, cable_state,
                       capacity_margin, distribute_tensions, external_wrench_box,
                       plan_deployment, resolve_redundancy, wrench_feasible,
                       wrench_feasible_workspace)
from taut.errors import InfeasiblePoseError

OUTCOMES = (TensionResult, RedundancyResult, DeploymentResult)


@pytest.mark.parametrize("cls", OUTCOMES)
def test_outcome_types_have_success_status_message(cls):
    names = {f.name for f in dataclasses.fields(cls)}
    assert {"success", "status", "message"} <= names
    assert not hasattr(cls, "feasible") and not hasattr(cls, "reason")     # one name each


def test_tension_outcome(fastkit):
    res = distribute_tensions(fastkit, [[0, 0, 0.6], [0, 0, 2.2]], "lp_min_sum")
    assert res.success.tolist() == [True, False]
    assert res.status.tolist() == ["ok", "infeasible"]
    assert res.binding.tolist() == ["", "limits"]
    assert set(res.status) <= set(STATUSES)
    assert res.message == "1 of 2 poses balanced within the tension and tipping limits"


def test_redundancy_outcome(fastkit):
    ok = resolve_redundancy(fastkit, [0.3, 0, 1.0], [0.5, 0, 0, 0, 0, 0])
    bad = resolve_redundancy(fastkit, [0.3, 0, 1.0], [50.0, 0, 0, 0, 0, 0])
    assert (ok.success, ok.status) == (True, "ok")
    assert (bad.success, bad.status) == (False, "infeasible") and bad.message != ""


def test_refuted_deployment_status(fastkit):
    res = plan_deployment(fastkit, [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]])
    assert (res.success, res.status, res.refuted) == (False, "refuted", True)
    assert res.lift_bound.status == "refuted" and not res.lift_bound.success
    with pytest.raises(ValueError):
        dataclasses.replace(res, status="nope")


def test_tipping_is_on_by_default(fastkit):
    """One default (True) across distribute_tensions, the AWS and the workspace."""
    for f in (distribute_tensions, wrench_feasible, cdpr.available_wrench_set,
              cdpr.axis_capacities, capacity_margin):
        assert inspect.signature(f).parameters["tipping"].default is True, f.__name__
    P = np.array([[x, 0.0, z] for x in np.linspace(-2.3, 2.3, 9) for z in (0.4, 1.2, 1.8)])
    d = distribute_tensions(fastkit, P, "lp_min_sum")
    t = distribute_tensions(fastkit, P, "lp_min_sum", tipping=True)
    f = distribute_tensions(fastkit, P, "lp_min_sum", tipping=False)
    assert d.tipping and not f.tipping
    np.testing.assert_array_equal(d.success, t.success)
    np.testing.assert_array_equal(d.success, wrench_feasible(fastkit, P))
    assert np.any(f.success & ~d.success)          # the default removes tipping poses


def test_external_wrench_is_the_one_name(fastkit):
    P = [[0, 0, 0.6], [1.0, 0, 1.2]]
    D = external_wrench_box(fastkit, [3, 3, 3, 0.3, 0.3, 0.3])
    new = wrench_feasible(fastkit, P, external_wrench=D)
    ws = wrench_feasible_workspace(fastkit, np.array(P), external_wrench=D)
    np.testing.assert_array_equal(ws.feasible_tipping, new)
    np.testing.assert_array_equal(capacity_margin(fastkit, P, external_wrench=D) > 0, new)
    for f in (wrench_feasible, capacity_margin, wrench_feasible_workspace):
        assert "disturbance" not in inspect.signature(f).parameters, f.__name__
    assert not hasattr(cdpr, "disturbance_box")


def test_cable_state_reports_the_offending_pose(point_mass):
    """Regression: the zero-length check and the reported index used different
    tolerances, so a length between them (here 2e-12 m, below 1e-12 * (1 + 3 m)) was
    caught but blamed on pose 0."""
    exit_ = point_mass.exits_world[1]
    poses = [[0.0, 0.0, 1.0], [0.1, 0.2, 1.5], exit_ - [2e-12, 0.0, 0.0]]
    with pytest.raises(InfeasiblePoseError, match="pose 2 puts an attachment point"):
        cable_state(point_mass, poses)
    with pytest.raises(InfeasiblePoseError, match="pose 0 "):
        cable_state(point_mass, [exit_, [0.0, 0.0, 1.0]])
    assert cable_state(point_mass, poses[:2]).lengths.shape == (2, 4)
