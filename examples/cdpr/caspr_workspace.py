"""Wrench-feasible workspace fractions of two CASPR models read with
``taut.io.caspr.load_caspr_model`` (files in ``caspr/``, BSD-3 from the CASPR toolbox).

Grid: 21 x 21 x 11 level poses over the box spanned by the exit points (the frame)
and the joint limits, shrunk by 5 % per side; weight only. Writes ``caspr_workspace.json``.
Run: ``python examples/cdpr/caspr_workspace.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from taut.cdpr import grid_points, wrench_closure, wrench_feasible_workspace
from taut.io.caspr import load_caspr_model

HERE = Path(__file__).resolve().parent


def main() -> None:
    out = {}
    for name in ("IPAnema_1", "CoGiRo"):
        robot = load_caspr_model(HERE / "caspr" / f"{name}_bodies.xml",
                                 HERE / "caspr" / f"{name}_cables.xml")
        lo = np.maximum(robot.exits_world.min(0), robot.bounds[0])
        hi = np.minimum(robot.exits_world.max(0), robot.bounds[1])
        lo[2] = max(robot.bounds[0, 2], 0.0)          # from the floor (suspended robots)
        pad = 0.05 * (hi - lo)
        box = np.stack([lo + pad, hi - pad])
        pts, shape = grid_points(box, (21, 21, 11))
        ws = wrench_feasible_workspace(robot, pts, shape=shape)
        out[name] = {"cables": robot.m, "dof": robot.dof, "mass_kg": robot.total_mass,
                     "box": np.round(box, 4).tolist(), "points": len(pts),
                     "wrench_feasible_%": round(100 * float(ws.feasible.mean()), 1),
                     "wrench_closure_%": round(100 * float(wrench_closure(robot, pts).mean()),
                                               1)}
    (HERE / "caspr_workspace.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    from taut.cli._progress import working  # progress on stderr past 2 s
    with working("caspr_workspace"):
        main()
