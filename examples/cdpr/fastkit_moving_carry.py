"""The active base driving during each carry of the kitting mission (issue 30, part 4: the
redundancy the FASTKIT paper leaves open), measured against the mission's standing base.

For every task of ``warehouse.yaml`` served by ``plan_mission``'s sites, the carry (0.1 m
lift, then across to 0.1 m above the place target) is planned three ways and each run in
the 1 kHz control simulation with the mission's monitors:

* ``standing``: the mission's law (both bases' stabilisers down, base still);
* ``wheels``: base still but its stabilisers up (what driving requires), offsets (0, 0);
* ``moving``: the active base driving from 0 to ``a1`` along the face during the across
  segment (:func:`taut.cdpr.mission.moving_carry.moving_carry`), for each ``a1`` of
  ``OFFSETS`` and ``a1`` = the platform's own displacement along the face.

Writes ``fastkit_moving_carry.json``. Run: ``python examples/cdpr/fastkit_moving_carry.py``
(about 2-4 min).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from taut.cdpr import DynamicsModel, time_optimal_path, with_box
from taut.cdpr.mission._execute import run_motion
from taut.cdpr.mission.mission import LIFT_M
from taut.cdpr.mission.moving_carry import moving_carry, run_moving_carry
from taut.cdpr.mission.sites import choose_sites
from taut.io import load_warehouse, write_json

HERE = Path(__file__).resolve().parent
#: End offsets of the active base tried, m (start 0: the site's placement).
OFFSETS = (-0.2, -0.1, -0.05, -0.02, 0.0, 0.02, 0.05, 0.1, 0.2)


def _row(kind: str, a1: float, duration: float, run) -> dict:
    return {"kind": kind, "a1_m": round(a1, 4), "duration_s": round(duration, 4),
            "success": bool(run.success), "min_tension_margin_N": round(run.min_tension_margin, 3),
            "min_tipping_margin_Nm": round(run.min_tipping_margin, 3),
            "min_sliding_margin_N": round(run.min_sliding_margin, 3)}


def _task(wh, site, name, pick, place, mass, dyn) -> list[dict]:
    lift = np.array([0.0, 0.0, LIFT_M])
    robot = with_box(site.robot, mass)
    wp = np.array([pick, pick + lift, place + lift])
    law = time_optimal_path(robot, wp, dynamics=dyn)
    rows = [_row("standing", 0.0, law.duration, run_motion(wh, site.pose, robot, law, dyn))]
    follow = float(place[0] - pick[0])           # active base x axis = robot-frame x
    for a1 in sorted(set(OFFSETS) | {round(follow, 4)}):
        carry = moving_carry(robot, wp, (0.0, a1), base_accel=wh.max_accel, dynamics=dyn)
        if not carry.law.success:
            rows.append({"kind": "moving", "a1_m": a1, "success": False,
                         "message": carry.law.message})
            continue
        run = run_moving_carry(wh, site.pose, robot, carry, dyn)
        rows.append(_row("wheels" if a1 == 0.0 else "moving", a1, carry.law.duration, run))
    return rows


def main() -> None:
    wh = load_warehouse(HERE / "warehouse.yaml")
    dyn = DynamicsModel()
    masses = {t.name: t.mass for t in wh.tasks}
    out = {}
    for site in choose_sites(wh).sites:
        for name, pick, place in zip(site.task_names, site.picks, site.places):
            rows = _task(wh, site, name, pick, place, masses[name], dyn)
            out[name] = rows
            ok = [r for r in rows if r.get("success") and r["kind"] == "moving"]
            best = min(ok, key=lambda r: r["duration_s"]) if ok else None
            print(name, rows[0], rows[[r["kind"] for r in rows].index("wheels")], best,
                  flush=True)
    write_json({"offsets_m": list(OFFSETS), "tasks": out},
               HERE / "fastkit_moving_carry.json")


if __name__ == "__main__":
    main()
