"""Planner and cable-robot endpoints (no web server needed), checked against the library."""

import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from taut.app.catalog import Catalog
from taut.app.cdpr_api import CdprAPI
from taut.app.plan_api import PlanAPI
from taut.cdpr import distribute_tensions, tipping_moments, wrench_feasible_workspace
from taut.errors import TautError
from taut.io import load_cdpr_model, load_plan_scenario, plan_scenario_from_mapping
from taut.plan import plan

ROOT = Path(__file__).parents[2]
CORRIDOR = ROOT / "examples" / "plan" / "paper_corridor.yaml"


@pytest.fixture(scope="module")
def cdpr():
    api = CdprAPI(Catalog(ROOT / "examples"))
    return api, api.load({"example": "fastkit"})["model"]


def run_job(client, sc, timeout=600.0):
    """Queue a planning job through the app and poll it to the end; returns the last
    reply and every stage seen."""
    r = client.post("/api/plan/run", json={"scenario": sc})
    assert r.status_code == 200, r.text
    jid, seen = r.json()["job"], set()
    deadline = time.monotonic() + timeout              # the machine may be shared
    while time.monotonic() < deadline:
        s = client.get(f"/api/plan/job/{jid}").json()
        seen.add(s["stage"])
        if s["state"] != "running":
            break
        time.sleep(0.05)
    # fetched once: the id is spent
    gone = client.get(f"/api/plan/job/{jid}")
    assert gone.status_code == 422 and gone.json()["error"].startswith("job: ")
    return s, seen


@pytest.mark.slow  # ~4 s of CPU: the slow target (CI runs it)
def test_planner_job_reports_progress_and_the_library_plan():
    pytest.importorskip("starlette.testclient", reason="needs the app-test extra")
    from starlette.testclient import TestClient

    from taut.app.server import create_app

    app = create_app(catalog=Catalog(ROOT / "examples"), workers=1)
    with TestClient(app, base_url="http://127.0.0.1:8765",
                    headers={"X-Taut-Token": app.state.token}) as client:
        sc = client.post("/api/plan/load", json={"example": CORRIDOR.name}).json()["scenario"]
        s, seen = run_job(client, sc)
        yaml_text = client.post("/api/plan/yaml", json={"scenario": sc}).json()["yaml"]
    assert s["state"] == "done" and s["steps"] == 2
    assert "planner with obstacle crossing" in seen or "SE(2) bypass baseline" in seen
    want = plan(load_plan_scenario(CORRIDOR))
    got = s["plan"]
    assert got["success"] and got["crossed"] == list(want.crossed)
    assert got["duration"] == pytest.approx(want.duration, rel=1e-12)
    np.testing.assert_allclose(got["object"], want.object, atol=1e-12)
    # The baseline is the SE(2) bypass (the disc model finds no route here).
    assert s["baseline"]["success"] is True and s["baseline"]["planner"] == "se2-bypass"
    assert s["world"]["start"] == [float(x) for x in load_plan_scenario(CORRIDOR).start]
    # Plots (taut.plan.plan_profile): the object clears every obstacle beneath by the
    # height safety; the sheet never tears (slack >= 0) and the least slack is the pair
    # slack of the first sample.
    over = [h for h in got["height_over_obstacle_m"] if h is not None]
    assert over and min(over) >= 0.05 - 1e-6
    V = load_plan_scenario(CORRIDOR).team.sheet.vertices
    R = want.robots[0]
    slack = min(np.linalg.norm(V[i] - V[j]) - np.linalg.norm(R[i] - R[j])
                for i in range(3) for j in range(i + 1, 3))
    assert got["sheet_slack_m"][0] == pytest.approx(slack, abs=1e-12)
    assert min(got["sheet_slack_m"]) >= -1e-9
    # The YAML download is a scenario `taut plan` reads back as the same problem.
    back = plan_scenario_from_mapping(yaml.safe_load(yaml_text))
    assert back.team.hold_height == 0.5 and len(back.world.obstacles) == 2


def test_bad_scenario_is_one_line_error():
    api = PlanAPI(Catalog(ROOT / "examples"))
    bad = yaml.safe_load(CORRIDOR.read_text())
    bad["team"]["hold_height"] = -1
    for call in (api.load, api.check, api.baseline, api.crossing):
        with pytest.raises(TautError, match=r"^team\.hold_height: "):
            call({"scenario": bad})


def test_planner_settings_are_the_library_s_and_go_to_it_unchanged():
    """The page's settings come from taut.plan.plan's signature; unknown names are the
    request's 422, bad values the library's own error line."""
    import inspect
    from taut.app.plan_api import SETTINGS, settings
    api = PlanAPI(Catalog(ROOT / "examples"))
    offered, params = settings(), inspect.signature(plan).parameters
    assert set(offered) == set(SETTINGS) | {"baseline"}
    assert offered["search"]["default"] == params["search"].default
    assert "lattice" in offered["search"]["choices"] and offered["baseline"]["choices"] == ["se2", "disc"]
    assert offered["sheet_margin"] == {"default": params["sheet_margin"].default, "choices": None}
    sc = yaml.safe_load(CORRIDOR.read_text())
    with pytest.raises(TautError, match=r"^options\.budget: unknown setting"):
        api.check({"scenario": sc, "options": {"budget": 1}})
    with pytest.raises(TautError, match=r"^iterations: must be an integer"):
        api.crossing({"scenario": sc, "options": {"iterations": "many"}})
    with pytest.raises(TautError, match=r"^search: unknown search"):
        api.baseline({"scenario": sc, "options": {"search": "bfs"}})


def test_feasible_pose_tensions_and_margins_are_the_library_s(cdpr):
    api, model = cdpr
    robot = load_cdpr_model("fastkit")
    pose = [0.3, 0.0, 0.8, 0.0, 0.0, 0.0]
    got = api.state({"model": model, "pose": pose, "method": "qp_min_norm"})
    want = distribute_tensions(robot, pose, "qp_min_norm")
    assert got["feasible"] is bool(want.success) is True
    assert got["message"] == want.message and got["binding"] == want.binding == ""
    np.testing.assert_allclose(got["tensions"], want.tensions, rtol=1e-12)
    moments = tipping_moments(robot, pose, want.tensions).moments
    for k, m in enumerate(got["margins"]):
        assert m["margin"] == pytest.approx(-moments[robot.edge_base == k].max(), abs=1e-9)


def test_pose_out_of_the_workspace_is_flagged(cdpr):
    api, model = cdpr
    robot = load_cdpr_model("fastkit")
    high = [0.0, 0.0, 2.3, 0.0, 0.0, 0.0]          # cables nearly horizontal
    got = api.state({"model": model, "pose": high, "method": "qp_min_norm"})
    want = distribute_tensions(robot, high, "qp_min_norm")
    assert not distribute_tensions(robot, high, "qp_min_norm", tipping=False).success
    assert got["feasible"] is False and got["feasible_limits"] is False
    assert got["message"] == want.message and got["message"].startswith("not wrench-feasible")
    assert got["binding"] == "limits"
    assert got["tensions"] is not None              # the closed form's attempt is shown
    outside = api.state({"model": model, "pose": [2.9, 0, 0.3, 0, 0, 0]})
    assert outside["in_frame"] is False and "outside the frame box" in outside["message"]


def test_workspace_slice_is_the_library_s(cdpr):
    api, model = cdpr
    robot = load_cdpr_model("fastkit")
    got = api.workspace({"model": model, "plane": "xz", "offset": 0.0, "n": [9, 5]})
    pts = np.array([[x, 0.0, z] for z in got["b"] for x in got["a"]])
    want = wrench_feasible_workspace(robot, pts)
    np.testing.assert_array_equal(np.ravel(got["feasible"]), want.feasible)
    np.testing.assert_array_equal(np.ravel(got["feasible_tipping"]), want.feasible_tipping)
    assert any(np.ravel(got["feasible"])) and not all(np.ravel(got["feasible"]))


def test_stabilisers_and_model_yaml(cdpr):
    api, model = cdpr
    pose = [0.0, 0.0, 0.8, 0.0, 0.0, 0.0]
    out = api.yaml({"model": model, "pose": pose, "stabilisers": True})
    assert "--pose 0 0 0.8" in out["yaml"] and "--stabilisers" in out["yaml"]
    back = yaml.safe_load(out["yaml"])
    assert back == model
    with pytest.raises(TautError, match="^n: "):
        api.workspace({"model": model, "n": [1000, 1000]})


def test_tipping_verdict_and_margins_are_the_library_s(cdpr):
    """The bases tip 1.2 m up (library default: tipping considered): the endpoint says so
    with the library's message, and its margins are the library's per-base ones."""
    api, model = cdpr
    robot = load_cdpr_model("fastkit")
    pose = [0.0, 0.0, 1.2, 0.0, 0.0, 0.0]
    got = api.state({"model": model, "pose": pose})
    want = distribute_tensions(robot, pose)
    limits = distribute_tensions(robot, pose, tipping=False, sliding=False)
    assert got["feasible"] is bool(want.success) is False
    assert got["feasible_limits"] is bool(limits.success) is True
    assert got["binding"] == want.binding == "tipping" and got["message"] == want.message
    assert "tip over" in got["message"] and got["method"] == want.method
    tip = tipping_moments(robot, pose, limits.tensions)
    assert [m["margin"] for m in got["margins"]] == pytest.approx(-tip.base_moment)
    assert [m["stable"] for m in got["margins"]] == tip.base_stable.tolist() == [False, False]


@pytest.mark.parametrize("pose", [[0.3, 0.0, 0.8, 0.0, 0.0, 0.0], [0.1, -0.2, 1.1, 0.4, -0.3, 1.2]])
def test_platform_outline_is_the_hull_of_the_library_s_attachments(cdpr, pose):
    """The app draws the platform from the reply (no hull in the JS): each view's outline
    is the convex hull of the library's attachment points projected on that view,
    checked against shapely's hull."""
    from shapely.geometry import MultiPoint, Polygon
    from taut.cdpr import cable_state
    api, model = cdpr
    robot = load_cdpr_model("fastkit")
    got = api.state({"model": model, "pose": pose})
    attach = np.asarray(pose[:3]) + cable_state(robot, np.asarray(pose)[None]).r[0]
    np.testing.assert_allclose(got["attachments"], attach, atol=1e-12)
    for view, k in (("xz", 2), ("xy", 1)):
        ring = np.asarray(got["outline_m"][view])
        want = MultiPoint(attach[:, [0, k]]).convex_hull
        assert Polygon(ring).is_valid and Polygon(ring).exterior.is_ccw
        assert Polygon(ring).symmetric_difference(want).area < 1e-12 * max(want.area, 1.0)
        assert len(ring) == len(want.exterior.coords) - 1        # no repeated or collinear
