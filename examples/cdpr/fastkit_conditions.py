"""Regenerate the numbers and figures of ``fastkit_conditions.md`` (issue 17):

* suspended (`fastkit`) vs fully constrained (`fastkit_fc`) FASTKIT: wrench-feasible
  coverage of the desired slice with tension limits, + tipping, and the wrench-closure
  fraction;
* how much of the desired slice sliding of the bases removes at mu = 0.3 and 0.6 (and
  0.1, 0.2 for context), stabilisers retracted and deployed;
* the interference-free fraction of the desired slice (level platform; ideal and 2 mm
  cables), and the coverage with the platform kept inside the exits' bounding box;
* ``fastkit_suspended_vs_fc.png``: the two presets side by side (binding condition,
  wrench-closure rings);
* ``fastkit_binding_slice.png``: the binding condition per position (mu = 0.3, stabilisers
  deployed) and ``fastkit_binding_3d.png``: the same over a 3D grid (mu = 0.2, retracted).

Writes ``fastkit_conditions.json``. Run: ``python examples/cdpr/fastkit_conditions.py``.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from taut.cdpr import (cable_interference, grid_points, with_friction, with_stabilisers,
                       wrench_closure, wrench_feasible_workspace)
from taut.io.cdpr_model import load_cdpr_model
from taut.viz.cdpr_binding import plot_binding
from taut.viz.cdpr_compare import plot_workspace_comparison

HERE = Path(__file__).resolve().parent
GRID = (41, 1, 21)                       # the desired slice y = 0: 861 positions
MUS = (0.1, 0.2, 0.3, 0.6)
CABLE_DIAMETERS = (0.0, 0.002)        # m: ideal cables, and the 2 mm braid the preset assumes


def pct(x: float | None) -> float | None:
    return None if x is None else round(100.0 * x, 1)


def coverage(robot) -> dict:
    pts, shape = grid_points(robot.desired_workspace, GRID)
    ws = wrench_feasible_workspace(robot, pts, shape=shape)
    out = {"limits_%": pct(ws.coverage), "tipping_%": pct(ws.coverage_tipping)}
    if ws.coverage_sliding is not None:
        out["sliding_%"] = pct(ws.coverage_sliding)
        out["binding_counts"] = {k or "feasible": int((ws.binding == k).sum())
                                 for k in ("", "limits", "tipping", "sliding")}
    return out


def interference(robot, pts) -> dict:
    """Interference-free fraction, level platform, for ideal (0) and 2 mm cables."""
    names = [c.name for c in robot.cables]
    out = {}
    for d in CABLE_DIAMETERS:
        itf = cable_interference(robot, pts, min_distance=d)
        meet = itf.distance <= d + 1e-9
        pairs = sorted({f"{names[i]}/{names[j]}" for i, j in zip(*np.nonzero(meet.any(0)))
                        if i < j})
        out[f"d={d}"] = {"free_%": pct(float(itf.free.mean())),
                         "cable_cable_%": pct(float(itf.cable_cable.mean())),
                         "cable_platform_%": pct(float(itf.cable_platform.any(axis=1).mean())),
                         "pairs_that_meet": pairs}
    return out


def main() -> None:
    out: dict = {"grid": list(GRID), "points": int(np.prod(GRID))}
    compare = []
    for name in ("fastkit", "fastkit_fc"):
        robot = load_cdpr_model(name)
        pts, shape = grid_points(robot.desired_workspace, GRID)
        ws = wrench_feasible_workspace(robot, pts, shape=shape, closure=True)
        compare.append((ws, robot))
        boxed = wrench_feasible_workspace(replace(robot, platform_inside_exits=True), pts,
                                          shape=shape)
        out[name] = {"retracted": coverage(robot),
                     "stabilisers": coverage(with_stabilisers(robot)),
                     "closure_%": pct(ws.coverage_closure),
                     "closure_check_%": pct(float(wrench_closure(robot, pts).mean())),
                     "inside_exits_box_%": pct(boxed.coverage_inside),
                     "sliding": {f"{'stabilisers' if stab else 'retracted'} mu={mu}":
                                 coverage(with_friction(with_stabilisers(robot, deployed=stab), mu))
                                 for stab in (False, True) for mu in (0.3, 0.6)}}
        light = robot.__class__(robot.bases, robot.platform, robot.cables,
                                gravity=robot.gravity, desired_workspace=robot.desired_workspace,
                                name=robot.name + " without payload")
        out[name]["no_payload"] = coverage(light)
        out[name]["interference"] = interference(robot, pts)
    plot_workspace_comparison([w for w, _ in compare], [r for _, r in compare],
                              HERE / "fastkit_suspended_vs_fc.png",
                              titles=["suspended FASTKIT (fastkit)",
                                      "fully constrained FASTKIT (fastkit_fc)"])
    robot = load_cdpr_model("fastkit")
    sliding = {}
    for stab in (False, True):
        base = with_stabilisers(robot, deployed=stab)
        ref = coverage(base)["tipping_%"]
        for mu in MUS:
            c = coverage(with_friction(base, mu))
            sliding[f"{'stabilisers' if stab else 'retracted'} mu={mu}"] = {
                **c, "removed_by_sliding_points_%": round(ref - c["sliding_%"], 1)}
    out["sliding"] = sliding
    fr = with_friction(with_stabilisers(robot), 0.3)
    pts, shape = grid_points(fr.desired_workspace, GRID)
    plot_binding(wrench_feasible_workspace(fr, pts, shape=shape), fr,
                 HERE / "fastkit_binding_slice.png",
                 title="FASTKIT, stabilisers deployed, mu = 0.3: binding condition (y = 0)")
    f3 = with_friction(robot, 0.2)
    pts3, shape3 = grid_points([[-2.5, -0.5, 0.2], [2.5, 0.5, 2.2]], (21, 5, 11))
    ws3 = wrench_feasible_workspace(f3, pts3, shape=shape3)
    plot_binding(ws3, f3, HERE / "fastkit_binding_3d.png", view="3d",
                 title="FASTKIT, stabilisers retracted, mu = 0.2: binding condition")
    out["grid_3d"] = {"box": [[-2.5, -0.5, 0.2], [2.5, 0.5, 2.2]], "shape": [21, 5, 11],
                      "binding_counts": {k or "feasible": int((ws3.binding == k).sum())
                                         for k in ("", "limits", "tipping", "sliding")}}
    (HERE / "fastkit_conditions.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    from taut.cli._progress import working  # progress on stderr past 2 s
    with working("fastkit_conditions"):
        main()
