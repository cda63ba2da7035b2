"""Screenshots of the app's views (the PNG files beside this script).

Usage::

    python examples/app/screenshots.py

Serves the app on a free localhost port, opens it in headless Chromium and saves:
``sheet_explorer.png`` (FK paper Example 2 after dragging robot 2, with its 3D view),
``sheet_simulate.png`` (the square team walking robot 3 outwards along
``square4_jump.csv`` until the object jumps, with the height and taut-set charts),
``planner.png`` (the paper corridor's plan, paused while crossing obstacle 2, with the
planner's settings) and ``cable_robot.png`` (FASTKIT with the platform lifted out of the
feasible workspace: side, top and 3D views and the tension chart). The charts are drawn
by the vendored Plotly.js (``src/taut/app/static/vendor``).
Needs the ``app-test`` extra and Debian's chromium + chromium-driver.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from taut.app.browser import chromium, drag, drag_at, find_browser, served, wait_for
from taut.app.catalog import Catalog
from taut.app.server import create_app
from taut.io.trajectory import load_trajectory

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def sheet(d) -> None:
    d.execute_script("SheetView.load({example: 'example2_r2_r4_353mm.yaml'})")
    wait_for(d, "SheetView.sc && SheetView.fk && !SheetView.inflight")
    drag(d, '.robot[data-i="1"]', [(2, 1)] * 12)
    wait_for(d, "!SheetView.inflight && SheetView.pendingT0 === null")
    time.sleep(0.5)                                    # the 3D view redraws at most every 0.15 s
    d.save_screenshot(str(HERE / "sheet_explorer.png"))


def simulate(d) -> None:
    traj = ROOT / "examples" / "sheet" / "trajectories"
    text = (traj / "square4.yaml").read_text()
    d.execute_script("SheetView.load({text: arguments[0], filename: 'square4.yaml'})", text)
    wait_for(d, "SheetView.sc && SheetView.sc.units === 'm' && SheetView.fk")
    path = load_trajectory(traj / "square4_jump.csv").formations.tolist()
    d.execute_script("document.querySelector('input[value=simulate]').click();"
                     "SheetView.formation = arguments[0][0]; SheetView.path = arguments[0];"
                     "SheetView.play()", path)
    wait_for(d, "document.getElementById('sim-events').textContent", timeout=60)
    wait_for(d, "!SheetView.playing && SheetView.fk && !SheetView.inflight", timeout=60)
    # Show the playback's last frame (object path and the jump marked) for the picture.
    d.execute_script("""const F = SheetView.densePath();
        api('/api/sheet/simulate', SheetView.body({formations: F})).then(r =>
          { SheetView.drawSimulation(F, r.data.simulation, F.length - 1); window.simDone = 1; });""")
    wait_for(d, "window.simDone")
    time.sleep(0.5)
    d.save_screenshot(str(HERE / "sheet_simulate.png"))


def planner(d) -> None:
    d.execute_script("showView('plan'); PlanView.load({example: 'paper_corridor.yaml'}, {run: true})")
    wait_for(d, "PlanView.result", timeout=120)
    d.execute_script("""const p = PlanView.result.plan;
        PlanView.k = p.times.findIndex(t => t >= p.times[p.times.length - 1] * 0.66);
        document.getElementById('plan-time').value = PlanView.k; PlanView.drawFrame();""")
    time.sleep(0.5)
    d.save_screenshot(str(HERE / "planner.png"))


def cable_robot(d) -> None:
    d.execute_script("showView('cdpr'); CdprView.load({example: 'fastkit'})")
    wait_for(d, "CdprView.st && CdprView.ws && !CdprView.inflight")
    d.execute_script("window.scrollTo(0, 0)")
    drag_at(d, d.execute_script("return CdprView.platformScreen('cdpr-side')"), [(0, -8)] * 14)
    wait_for(d, "!CdprView.inflight && !CdprView.pending && CdprView.st.feasible === false")
    time.sleep(0.5)                                    # the 3D view's WebGL frame
    d.save_screenshot(str(HERE / "cable_robot.png"))


def main() -> int:
    found = find_browser()
    if found is None:
        raise SystemExit("needs Chromium: apt-get install -y chromium chromium-driver")
    with served(create_app(catalog=Catalog(ROOT / "examples"))) as url, chromium(*found) as d:
        d.set_window_size(1400, 1250)
        d.get(url)
        wait_for(d, "document.body.dataset.ready")
        for shot in (sheet, simulate, planner, cable_robot):
            shot(d)
            print(f"{shot.__name__}: done")
    return 0


if __name__ == "__main__":
    from taut.cli._progress import working  # progress on stderr past 2 s
    with working("screenshots"):
        code = main()
    sys.exit(code)
