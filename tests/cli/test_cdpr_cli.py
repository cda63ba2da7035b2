"""`taut cdpr deploy` with the optimiser stubbed: the CLI maps a verified placement to exit 0
and a failed search to exit 1 (pinned, not "either"), in seconds instead of minutes."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

import taut.cdpr
from taut.cli import main

BOX = ["-1", "1", "-0.05", "0.05", "0.4", "0.9"]


def _fake(feasible: bool, calls: list):
    def plan_deployment(robot, box, **kw):
        calls.append((np.asarray(box).tolist(), kw))
        n = 4
        return SimpleNamespace(
            success=feasible, feasible=feasible, refuted=False, robot=robot,
            base_poses={"active": np.array([-3.0, 0.1, 0.0]),
                        "passive": np.array([3.0, -0.1, 3.14])},
            margin=0.5 if feasible else -0.25, twist_margin=None,
            points=np.zeros((n, 3)), point_feasible=np.array([feasible] * n),
            point_margin=np.zeros(n), workspace=np.asarray(box), evaluations=7,
            message="" if feasible else "budget exhausted: 3 of 4 points infeasible",
            reason="" if feasible else "budget exhausted: 3 of 4 points infeasible",
            lift_bound=None)
    return plan_deployment


@pytest.mark.parametrize("feasible, code", [(True, 0), (False, 1)])
def test_deploy_exit_code_is_pinned(capsys, monkeypatch, feasible, code):
    calls: list = []
    monkeypatch.setattr(taut.cdpr, "plan_deployment", _fake(feasible, calls))
    assert main(["cdpr", "deploy", "fastkit", "--workspace", *BOX, "--json",
                 "--seed", "3", "--maxiter", "2"]) == code
    doc = json.loads(capsys.readouterr().out)
    assert doc["feasible"] is feasible and doc["evaluations"] == 7
    assert calls[0][0] == [[-1.0, -0.05, 0.4], [1.0, 0.05, 0.9]]      # XMIN XMAX ... order
    assert calls[0][1]["seed"] == 3 and calls[0][1]["maxiter"] == 2
    assert main(["cdpr", "deploy", "fastkit", "--workspace", *BOX]) == code
    text = capsys.readouterr().out
    assert ("FEASIBLE" if feasible else "NOT FOUND") in text.splitlines()[0]
    if not feasible:
        assert "budget exhausted" in text
