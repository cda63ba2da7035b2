"""Deployment with the active base moving during the task (issue 17, FASTKIT §2: task
mode moves the active base): the tallest verified box with a fixed placement vs a
two-stage schedule of the active base (``taut.cdpr.plan_moving_deployment``: between the
stages the active base drives on its wheels, stabilisers retracted, while the platform
waits on the shared face), same box extent, payload, stabilisers, required twist and
search settings as the fixed-placement numbers of ``fastkit_motion.md``.

Writes ``fastkit_moving_base.json``. Run: ``python examples/cdpr/fastkit_moving_base.py``
(about 25 minutes on a loaded 2-core machine).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from taut.cdpr import tallest_workspace, with_stabilisers
from taut.io.cdpr_model import load_cdpr_model

HERE = Path(__file__).resolve().parent
FULL = [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]]
PLAN = dict(required_twist=[1.0, 0, 0, 0, 0, 0], maxiter=6, popsize=6,
            search=(1.5, 0.5, 0.6), grid=(6, 2, 4), verify_grid=(21, 3, 9), seed=0)
STAGES = 2
_T0 = time.monotonic()


def step(what: str) -> None:
    print(f"[{time.monotonic() - _T0:6.0f} s] {what}", file=sys.stderr, flush=True)


def poses(d: dict) -> dict:
    return {k: [round(float(x), 4) for x in v] for k, v in d.items()}


def main() -> None:
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    out: dict = {"stages": STAGES, "plan": {k: list(v) if isinstance(v, (list, tuple)) else v
                                            for k, v in PLAN.items()}}
    step(f"tallest box, {STAGES} stages (bisection, tol 0.05 m)")
    top = float(robot.exits_world[:, 2].max())
    tw = tallest_workspace(robot, [FULL[0], [FULL[1][0], FULL[1][1], top]], tol=0.05,
                           stages=STAGES, **PLAN)
    dep = tw.deployment
    out["tallest_moving"] = {
        "height": None if dep is None else round(float(tw.height), 4),
        "certified_limit": round(float(tw.certified_limit), 4),
        "failed_below": None if np.isnan(tw.failed_below) else round(tw.failed_below, 4),
        "tried": [[round(z, 4), ok] for z, ok in tw.tried],
        "stage_poses": None if dep is None else [poses(p) for p in dep.base_poses],
        "transition_wait_m": None if dep is None else np.round(dep.transition_wait_m,
                                                               4).tolist(),
        "margin": None if dep is None else round(float(dep.margin), 4)}
    (HERE / "fastkit_moving_base.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))
    step("done")


if __name__ == "__main__":
    main()
