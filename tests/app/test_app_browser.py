"""The app in a real browser (headless Chromium driven by Selenium): drag robot 2 of
Example 2 and compare the displayed equilibria with forward_kinematics; play the paper
corridor's plan to its end; push the cable robot's platform out of the feasible
workspace and see it flagged; bad uploads, shared links and YAML and plan downloads.
The charts (Plotly.js, vendored) are checked for the library's numbers and for axis titles
with units; the 3D cable-robot view for the library's cable geometry.

Skipped, with the reason, when Chromium, chromedriver or the app extras are missing.
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from taut.cdpr import cable_state, distribute_tensions
from taut._geometry import convex_hull_2d
from taut.errors import InfeasibleFormationError
from taut.io import load_cdpr_model, load_plan_scenario, load_sheet_scenario, \
    sheet_scenario_from_mapping
from taut.plan import plan
from taut.sheet import forward_kinematics

pytestmark = pytest.mark.browser

ROOT = Path(__file__).parents[2]
EX2 = ROOT / "examples" / "sheet" / "example2_r2_r4_353mm.yaml"


@pytest.fixture(scope="module")
def page(browser_paths):
    binary, driver = browser_paths
    from taut.app.browser import chromium, served
    from taut.app.catalog import Catalog
    from taut.app.server import create_app

    with served(create_app(catalog=Catalog(ROOT / "examples"))) as url, \
            chromium(binary, driver) as d:
        d.get(url)
        wait_for(d, "document.body.dataset.ready")
        d.base_url = url
        yield d


def wait_for(d, script, timeout=60.0):
    """Wait for the page; generous, because what is tested is the outcome, not the time
    (on a loaded 2-core machine a first FK with a cold numba cache can take tens of s)."""
    from taut.app.browser import wait_for as wait
    return wait(d, script, timeout)


def drag(d, css, moves):
    from taut.app.browser import drag as real_drag
    real_drag(d, css, moves)


def drag_platform(d, view, moves):
    """Press on the platform where the chart ``view`` draws it and drag it."""
    from taut.app.browser import drag_at
    d.execute_script("document.getElementById(arguments[0]).scrollIntoView()", view)
    drag_at(d, d.execute_script("return CdprView.platformScreen(arguments[0])", view), moves)


def chart_titles(d):
    """{chart id: axis titles} of the charts on show; a categorical axis (cable names)
    is reported as "category"."""
    return {c["id"]: c["axes"] for c in d.execute_script("""return chartAxes().map(c => {
        const fl = document.getElementById(c.id)._fullLayout;
        if (!fl.scene && fl.yaxis.type === 'category') c.axes[1] = 'category';
        return c; })""")}


def assert_units(titles):
    for chart, axes in titles.items():
        for t in axes:
            assert t == "category" or re.search(r"\[[^\]]+\]$", t), (chart, t)


def trace(d, chart, name):
    """The data of the trace called ``name`` on a chart."""
    return d.execute_script("""return document.getElementById(arguments[0]).data
        .find(t => t.name === arguments[1])""", chart, name)


def by_id(d, name):
    from selenium.webdriver.common.by import By
    return d.find_element(By.ID, name)


def select(d, name, value):
    from selenium.webdriver.support.ui import Select
    Select(by_id(d, name)).select_by_value(value)


def settled_sheet(d):
    """Wait until no FK request is pending and return (formation shown, table rows)."""
    wait_for(d, "!SheetView.inflight && SheetView.pendingT0 === null && SheetView.fk")
    f = d.execute_script("return SheetView.fkFormation")
    rows = d.execute_script("""return [...document.querySelectorAll('#sheet-table tr.equilibrium-row')]
        .map(r => [...r.cells].map(c => c.textContent))""")
    return np.array(f), rows


def load_example2(d):
    by_id(d, "tab-sheet").click()
    d.execute_script("SheetView.sc = null; document.getElementById('sheet-example').value = '(choose)'")
    select(d, "sheet-example", EX2.name)
    wait_for(d, "SheetView.sc && SheetView.sc.name && SheetView.sc.name.startsWith('FK paper Example 2')"
                " && SheetView.fk && !SheetView.inflight")


def test_drag_robot_2_shows_the_fk_equilibria(page):
    d = page
    load_example2(d)
    sc = load_sheet_scenario(EX2)
    before, _ = settled_sheet(d)
    np.testing.assert_allclose(before, sc.formation)
    drag(d, '.robot[data-i="1"]', [(2, 1)] * 15 + [(1, -1)] * 10)
    f, rows = settled_sheet(d)
    assert np.linalg.norm(f[1] - sc.formation[1]) > 10.0          # robot 2 moved (mm)
    np.testing.assert_array_equal(np.delete(f, 1, 0), np.delete(sc.formation, 1, 0))
    res = forward_kinematics(sc.team, f)
    assert len(rows) == len(res.equilibria) > 0
    for row, e in zip(rows, res.equilibria):
        assert row[1] == "{" + ",".join(str(i + 1) for i in e.taut) + "}"
        shown = [float(v) for v in row[2:5]]
        np.testing.assert_allclose(shown, e.object, atol=0.0051)  # shown to 0.01 mm
        assert row[5] == e.kind
        if e.tensions is None:
            assert row[6] == "-"
        else:
            np.testing.assert_allclose([float(t) for t in row[6].split(",")], e.tensions,
                                       atol=0.00051)
    status = by_id(d, "sheet-status").text
    low = res.lowest
    assert f"{len(res.stable)} stable" in status
    assert f"object height {low.height:.2f} mm" in status
    for view, axes in (("sheet-top", ["x [mm]", "y [mm]"]),
                       ("sheet-frame", ["x, sheet frame [mm]", "y, sheet frame [mm]"])):
        assert d.execute_script("return [...document.querySelectorAll(`#${arguments[0]} .axis-title`)]"
                                ".map(t => t.textContent)", view) == axes
    wait_for(d, "SheetView.view3d.timer === null && document.getElementById('sheet-3d').data")
    assert chart_titles(d)["sheet-3d"] == ["x [mm]", "y [mm]", "z [mm]"]


def test_dragging_too_far_names_the_pair(page):
    d = page
    load_example2(d)
    drag(d, '.robot[data-i="1"]', [(12, -10)] * 12)
    f, rows = settled_sheet(d)
    sc = load_sheet_scenario(EX2)
    with pytest.raises(InfeasibleFormationError) as info:
        forward_kinematics(sc.team, f)
    i, j = info.value.pair
    status = by_id(d, "sheet-status").text
    assert status.startswith(f"INFEASIBLE formation: robots {i + 1} and {j + 1} are too far apart")
    assert rows == [] and d.execute_script("return document.querySelectorAll('.infeasible-pair').length") == 1


def test_bad_upload_shows_the_cli_line_and_keeps_the_state(page, tmp_path):
    d = page
    load_example2(d)
    f0, rows0 = settled_sheet(d)
    bad = tmp_path / "torn.yaml"
    bad.write_text("hold_height: 1000\nsheet: [[0, 0], [1, 0], [0, 1]]\n"
                   "formation: [[0, 0], [5, 0], [0, 1]]\n")
    by_id(d, "sheet-upload").send_keys(str(bad))
    msg = wait_for(d, "document.getElementById('message').className === 'error' && "
                      "document.getElementById('message').textContent")
    from taut.errors import TautError
    with pytest.raises(TautError) as info:
        load_sheet_scenario(bad)
    assert msg == str(info.value)
    f1, rows1 = settled_sheet(d)
    np.testing.assert_array_equal(f0, f1)
    assert rows0 == rows1


def test_link_and_yaml_reproduce_the_view(page):
    d = page
    load_example2(d)
    drag(d, '.robot[data-i="2"]', [(-2, 2)] * 10)
    f, rows = settled_sheet(d)
    url = d.current_url
    assert "#" in url
    d.execute_script("taut.lastYaml = null")
    by_id(d, "download").click()
    text = wait_for(d, "taut.lastYaml")
    back = sheet_scenario_from_mapping(yaml.safe_load(text))
    np.testing.assert_allclose(back.formation, f, rtol=0, atol=1e-9)
    d.get("about:blank")
    d.get(url)
    wait_for(d, "document.body.dataset.ready")
    f2, rows2 = settled_sheet(d)
    np.testing.assert_allclose(f2, f, rtol=0, atol=1e-9)
    assert rows2 == rows


def test_paper_corridor_plays_to_the_end(page, tmp_path):
    d = page
    by_id(d, "tab-plan").click()
    select(d, "plan-example", "paper_corridor.yaml")
    wait_for(d, "PlanView.world && !PlanView.result")
    select(d, "plan-opt-search", "lattice")
    margin = by_id(d, "plan-opt-sheet_margin")
    margin.clear()
    margin.send_keys("0.02")
    by_id(d, "plan-run").click()
    wait_for(d, "PlanView.result", timeout=120)
    sc = load_plan_scenario(ROOT / "examples" / "plan" / "paper_corridor.yaml")
    want = plan(sc, search="lattice", sheet_margin=0.02)
    select(d, "plan-speed", "50")
    by_id(d, "plan-play").click()
    wait_for(d, "document.getElementById('plan-clock').dataset.end === '1'", timeout=30)
    clock = by_id(d, "plan-clock").text
    m = re.match(r"t = ([\d.]+) s / ([\d.]+) s, object height ([\d.]+) m \(end\)", clock)
    assert m, clock
    assert float(m.group(1)) == pytest.approx(want.times[-1], abs=0.006)
    assert float(m.group(2)) == pytest.approx(want.duration, abs=0.006)
    assert float(m.group(3)) == pytest.approx(want.object[-1, 2], abs=0.0006)
    obj = d.execute_script("const p = PlanView.result.plan; return p.object[PlanView.k]")
    np.testing.assert_allclose(obj, want.object[-1], atol=1e-9)
    rows = d.execute_script("""return [...document.querySelectorAll('#plan-compare tr')].slice(1)
        .map(r => [...r.cells].map(c => c.textContent))""")
    assert rows[0][1] == "yes" and rows[0][4] == ", ".join(want.crossed)
    bypass = plan(sc, baseline="se2", search="lattice", sheet_margin=0.02, time_budget=30.0)
    assert rows[1][0].startswith("baseline (SE(2) bypass") and rows[1][1] == "yes"
    assert rows[1][3] == f"{bypass.path_length:.3f}" and rows[1][4] == "-"
    # the charts: the library's profile, axes with units
    height = trace(d, "plan-height", "object height")
    np.testing.assert_allclose(height["x"], want.times, atol=1e-12)
    np.testing.assert_allclose(height["y"], want.object[:, 2], atol=1e-12)
    titles = chart_titles(d)
    assert set(titles) == {"plan-top", "plan-height", "plan-margin"}
    assert titles["plan-top"] == ["x [m]", "y [m]"]
    assert_units(titles)
    # the download is the file `taut plan --out` writes for these settings
    d.execute_script("taut.lastPlanJson = null")
    by_id(d, "plan-save-json").click()
    doc = json.loads(wait_for(d, "taut.lastPlanJson"))
    from taut.io.serialize import plan_to_dict
    ref = json.loads(json.dumps(plan_to_dict(want)))
    assert doc.keys() == ref.keys() and doc["crossed"] == ref["crossed"]
    np.testing.assert_allclose(doc["object"], ref["object"], atol=1e-12)
    # and the ROS 2 recording is the one taut.io.write_mcap writes
    pytest.importorskip("mcap", reason="the MCAP download needs the mcap extra")
    by_id(d, "plan-save-mcap").click()
    wait_for(d, "taut.lastPlanMcap")
    import base64
    from taut.io import write_mcap
    got = base64.b64decode(d.execute_script("return PlanView.result.plan_mcap"))
    assert got == write_mcap(want, tmp_path / "plan.mcap").read_bytes()


def test_cable_robot_out_of_the_workspace_is_flagged(page):
    d = page
    by_id(d, "tab-cdpr").click()
    select(d, "cdpr-example", "fastkit")
    wait_for(d, "CdprView.st && CdprView.ws && !CdprView.inflight")
    robot = load_cdpr_model("fastkit")
    pose = d.execute_script("return CdprView.st.pose")
    assert distribute_tensions(robot, pose, "qp_min_norm", tipping=True).success
    assert by_id(d, "cdpr-flag").get_attribute("data-feasible") == "1"
    drag_platform(d, "cdpr-side", [(0, -8)] * 14)                   # lift it high
    wait_for(d, "!CdprView.inflight && !CdprView.pending")
    pose = d.execute_script("return CdprView.st.pose")
    assert pose[2] > 1.9
    want = distribute_tensions(robot, pose, "qp_min_norm", tipping=True)
    assert not want.success
    flag = by_id(d, "cdpr-flag")
    assert flag.get_attribute("data-feasible") == "0"
    assert flag.text == want.message and flag.text.startswith("not wrench-feasible")
    # the 3D view draws the library's cables: exit points to attachment points
    wait_for(d, "CdprView.timer3d === null && document.getElementById('cdpr-3d').data")
    st = cable_state(robot, np.array(pose)[None])
    ends = np.vstack([robot.exits_world, np.array(pose[:3]) + st.r[0]])
    shown = [trace(d, "cdpr-3d", n) for n in ("cable within limits", "cable off its limits")]
    pts = np.array([p for t in shown if t for p in zip(t["x"], t["y"], t["z"]) if p[0] is not None])
    assert len(pts) == 2 * robot.m
    for p in pts:
        assert np.min(np.linalg.norm(ends - p, axis=1)) < 1e-9
    # the 2D views draw the platform as the library's hull of its attachment points
    for view, k in (("cdpr-side", 2), ("cdpr-top", 1)):
        hull = convex_hull_2d(ends[robot.m:][:, [0, k]])
        drawn = trace(d, view, "platform (drag it)")
        np.testing.assert_allclose(np.column_stack([drawn["x"], drawn["y"]]),
                                   np.vstack([hull, hull[:1]]), atol=1e-9)
    # the tension chart shows the reply's tensions against the library's limits
    limits = trace(d, "cdpr-bars", "limits [t_min, t_max]")
    np.testing.assert_allclose([v for v in limits["x"] if v is not None],
                               np.column_stack([robot.t_min, robot.t_max]).ravel())
    titles = chart_titles(d)
    assert set(titles) == {"cdpr-side", "cdpr-top", "cdpr-3d", "cdpr-bars"}
    assert titles["cdpr-3d"] == ["x [m]", "y [m]", "z [m]"]
    assert_units(titles)


def test_ik_click_moves_the_robots_to_the_library_formation(page):
    d = page
    load_example2(d)
    f0, _ = settled_sheet(d)
    d.execute_script("document.querySelector('input[value=ik]').click();"
                     "document.getElementById('ik-height').value = 420;")
    from selenium.webdriver.common.action_chains import ActionChains
    ActionChains(d).move_to_element_with_offset(by_id(d, "sheet-top"), 15, -10).click().perform()
    wait_for(d, "document.getElementById('message').textContent.startsWith('IK:')")
    f, rows = settled_sheet(d)
    d.execute_script("document.querySelector('input[value=drag]').click()")
    target = d.execute_script("return SheetView.lastTarget")
    sc = load_sheet_scenario(EX2)
    from taut.sheet import inverse_kinematics
    want = inverse_kinematics(sc.team, target, reference=f0)
    np.testing.assert_allclose(f, want.formation, atol=1e-9)
    assert target[2] == 420
    stable = [r for r in rows if r[5] == "stable"]
    assert any(abs(float(r[4]) - 420) < 0.006 and abs(float(r[2]) - target[0]) < 0.006
               for r in stable)


def test_simulate_plays_the_path_and_marks_the_jump(page):
    d = page
    by_id(d, "tab-sheet").click()
    traj = ROOT / "examples" / "sheet" / "trajectories"
    d.execute_script("SheetView.sc = null; SheetView.load({text: arguments[0], filename: 'square4.yaml'})",
                     (traj / "square4.yaml").read_text())
    wait_for(d, "SheetView.sc && SheetView.sc.units === 'm' && SheetView.fk && !SheetView.inflight")
    from taut.io.trajectory import load_trajectory
    from taut.sheet import simulate
    path = load_trajectory(traj / "square4_jump.csv").formations
    # The recorded path is set directly (a recorded drag gives the same list of formations).
    d.execute_script("document.getElementById('sim-events').textContent = '';"
                     "document.querySelector('input[value=simulate]').click();"
                     "SheetView.formation = arguments[0][0]; SheetView.path = arguments[0];"
                     "SheetView.play()", path.tolist())
    text = wait_for(d, "document.getElementById('sim-events').textContent", timeout=60)
    wait_for(d, "!SheetView.playing", timeout=60)
    d.execute_script("document.querySelector('input[value=drag]').click()")
    dense = np.array(d.execute_script("return SheetView.densePath()"))
    want = simulate(load_sheet_scenario(traj / "square4.yaml").team, dense)   # z_r 1.5, 0.5 kg
    assert want.jumps
    j = want.jumps[0]
    assert text.startswith(f"jump at step {j.step}/{len(dense) - 1}: taut "
                           f"{{{','.join(str(i + 1) for i in j.taut_before)}}} -> "
                           f"{{{','.join(str(i + 1) for i in j.taut_after)}}}, drop {j.drop:.2f} m")
    # the height and taut-set charts are the library's simulation
    height = trace(d, "sim-height", "object height")
    np.testing.assert_allclose(np.array(height["y"], dtype=float), want.object[:, 2], atol=1e-9,
                               equal_nan=True)
    assert trace(d, "sim-height", "jump")["x"] == [e.step for e in want.jumps]
    taut = trace(d, "sim-taut", "cable taut")
    n, steps = want.formations.shape[1], len(want.taut)
    rows = np.array([v for v in taut["y"]], dtype=object).reshape(n, steps + 1)[:, :steps]
    for i in range(n):
        assert [v == i + 1 for v in rows[i]] == [i in t for t in want.taut]
    wait_for(d, "SheetView.view3d.timer === null")              # the 3D view follows
    titles = chart_titles(d)
    assert titles["sim-height"] == ["step along the path [index]", "object height [m]"]
    assert titles["sheet-3d"] == ["x [m]", "y [m]", "z [m]"]
    assert_units(titles)
    # the 3D view's caption says what it shows: the lowest stable state again after the
    # playback (FK of the last formation), a step of the simulation during it
    caption = "document.getElementById('sheet-3d-caption').textContent"
    wait_for(d, f"{caption}.startsWith('3D: lowest stable state')")    # FK again after play
    d.execute_script("SheetView.drawSimulation(arguments[0], SheetView.sim, 3)", dense.tolist())
    assert d.execute_script(f"return {caption}") == \
        f"3D: simulated state at step 3/{len(dense) - 1} (drag to turn)"


def test_cable_robot_link_reproduces_the_pose(page):
    d = page
    by_id(d, "tab-cdpr").click()
    select(d, "cdpr-example", "ipanema")
    wait_for(d, "CdprView.geo && CdprView.geo.name !== 'fastkit' && CdprView.st && !CdprView.inflight")
    drag_platform(d, "cdpr-top", [(3, 2)] * 8)
    wait_for(d, "!CdprView.inflight && !CdprView.pending")
    pose = d.execute_script("return CdprView.st.pose")
    flag = by_id(d, "cdpr-flag").text
    url = d.current_url
    d.get("about:blank")
    d.get(url)
    wait_for(d, "document.body.dataset.ready && CdprView.st && !CdprView.inflight")
    np.testing.assert_allclose(d.execute_script("return CdprView.st.pose"), pose, atol=1e-12)
    assert by_id(d, "cdpr-flag").text == flag
    robot = load_cdpr_model("ipanema")
    ok = distribute_tensions(robot, pose, "qp_min_norm", tipping=True).success
    assert flag.startswith("wrench-feasible" if ok else "NOT wrench-feasible")
