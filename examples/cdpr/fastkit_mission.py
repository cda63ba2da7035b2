"""The FASTKIT kitting mission end to end (issue 30) on ``warehouse.yaml``: two racks, a
kitting station, eight boxes, one out of reach.

``plan_mission`` chooses the deployment sites, plans the routes of the coupled bases, plans
every pick / carry / place motion time-optimally under the cable tensions with inertia, the
winches and the bases' tipping and sliding, runs every motion in the 1 kHz control
simulation (torque control on encoder-estimated states) and compares with the same mission
on a fixed 1 m/s trapezoidal profile under the same limits.

Writes ``fastkit_mission.json`` (the result's JSON form plus the time ratios) and
``fastkit_mission.png`` (floor plan, timeline, per-phase margins).
Run: ``python examples/cdpr/fastkit_mission.py`` (about 20-40 s).
"""

from __future__ import annotations

import time
from pathlib import Path

from taut.cdpr import plan_mission
from taut.io import load_warehouse, write_json
from taut.io.serialize import mission_to_dict
from taut.viz.cdpr_mission import plot_mission

HERE = Path(__file__).resolve().parent


def main() -> None:
    wh = load_warehouse(HERE / "warehouse.yaml")
    t0 = time.perf_counter()
    res = plan_mission(wh)
    wall = time.perf_counter() - t0
    print(res.message)
    for p in res.phases:
        print(f"  {p.kind:>8} {p.task or '-':>5} site {p.site + 1}: {p.start:7.2f}-{p.end:7.2f} s"
              f"  tension margin {p.min_tension_margin:6.2f} N"
              f"  tipping margin {p.min_tipping_margin:7.1f} N m")
    ratio = res.total_time / res.baseline_total_time
    motion = res.motion_time / res.baseline_motion_time
    print(f"total {res.total_time:.1f} s vs baseline {res.baseline_total_time:.1f} s "
          f"(ratio {ratio:.3f}); platform motions {res.motion_time:.1f} s vs "
          f"{res.baseline_motion_time:.1f} s (ratio {motion:.3f}); wall time {wall:.0f} s")
    doc = mission_to_dict(res)
    doc["ratio_total"] = round(ratio, 4)
    doc["ratio_motion"] = round(motion, 4)
    write_json(doc, HERE / "fastkit_mission.json")
    plot_mission(wh, res, HERE / "fastkit_mission.png")


if __name__ == "__main__":
    main()
