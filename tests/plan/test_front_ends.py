"""The planner's front ends give the library's answer: ``taut plan --json`` is
:func:`taut.plan.plan` on the same file, and the web app's planner view compares the plan
with the SE(2) bypass baseline (which finds a way on the paper corridor, where the disc
model finds none)."""

import json

import pytest

from taut.app.catalog import Catalog
from taut.app.plan_api import PLAN_TIME_CAP_S, PlanAPI
from taut.cli import main
from taut.io import load_plan_scenario
from taut.plan import plan

from .test_plan import EXAMPLES

CORRIDOR = EXAMPLES / "paper_corridor.yaml"


def test_cli_json_is_the_library_plan(capsys):
    capsys.readouterr()
    rc = main(["plan", str(CORRIDOR), "--json"])
    doc = json.loads(capsys.readouterr().out)
    want = plan(load_plan_scenario(CORRIDOR))
    assert rc == 0 and doc["success"] is want.success is True
    assert doc["path_length"] == want.path_length
    assert doc["duration"] == want.duration
    assert doc["crossed"] == list(want.crossed) and doc["planner"] == want.planner


def test_cli_names_its_option_in_the_library_s_range_error(capsys):
    assert main(["plan", str(CORRIDOR), "--sheet-margin", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["taut: error: --sheet-margin: 2 exceeds the accepted range 1 m"]
    assert main(["plan", str(CORRIDOR), "--budget", "7200"]) == 2
    assert capsys.readouterr().err.startswith("taut: error: --budget: 7200 exceeds")


def test_app_compares_with_the_se2_bypass_baseline():
    api = PlanAPI(Catalog(EXAMPLES.parent))
    sc = api.load({"example": CORRIDOR.name})["scenario"]
    base = api.baseline({"scenario": sc})["baseline"]      # the app job's first step
    want = plan(load_plan_scenario(CORRIDOR), baseline="se2", time_budget=PLAN_TIME_CAP_S)
    assert base["success"] is want.success is True and base["planner"] == "se2-bypass"
    assert "no route" not in base["message"]
    assert base["path_length"] == pytest.approx(want.path_length, rel=1e-12)
    assert base["path_length"] == pytest.approx(4.55, abs=0.005)
    assert base["crossed"] == [] and len(base["sheet_slack_m"]) == len(base["times"])
