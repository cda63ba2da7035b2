"""JSON endpoints of the planner viewer: load a planning scenario, run the planner and the
bypass-only baseline in a background job (the page polls its progress), and return both
plans with the series the page plots.

Planning is :func:`taut.plan.plan` and :func:`taut.plan.plan_baseline`; this module only
reshapes their results for drawing. Lengths m, times s.
"""

from __future__ import annotations

import dataclasses
import itertools
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field as dc_field
from typing import Any

import numpy as np
import shapely
import yaml

from ..io.serialize import plan_to_dict
from ..errors import ScenarioError, TautError
from ..io import plan_scenario_from_mapping, plan_scenario_to_mapping
from ..plan import PlanResult, Scenario, plan, plan_baseline
from .catalog import Catalog
from .payload import field, mapping_from_upload

__all__ = ["PlanAPI", "plan_series", "world_to_dict"]

#: Finished jobs kept for the page to collect.
_KEEP_JOBS = 16
#: Wall-clock cap of one planning job, s: the app stays interactive (the planner's own
#: budget is counted in samples; a failing plan could otherwise search for minutes).
PLAN_TIME_CAP_S = 30.0


def world_to_dict(sc: Scenario) -> dict[str, Any]:
    """Geometry for drawing: walls, obstacle footprints (circles as polygons) and heights,
    start, goal, the team's sheet, hold height and robot radius."""
    return {
        "free_space": np.asarray(sc.world.free_space).tolist(),
        "obstacles": [{"id": o.id, "height": float(o.height),
                       "polygon": np.asarray(o.geometry.exterior.coords)[:-1].tolist()}
                      for o in sc.world.obstacles],
        "start": [float(x) for x in sc.start], "goal": [float(x) for x in sc.goal],
        "sheet": np.asarray(sc.team.sheet.vertices).tolist(),
        "hold_height": float(sc.team.hold_height),
        "robot_radius": float(sc.team.robot_radius),
        "height_safety": float(sc.team.height_safety),
    }


def plan_series(sc: Scenario, r: PlanResult) -> dict[str, list[float | None]]:
    """Per-sample series of a plan for the viewer's plots.

    ``beneath``: height of the tallest obstacle whose footprint meets the robots' convex
    hull (0 when none), m. ``height_over_obstacle``: object height minus that (null when
    no obstacle is beneath), m. ``sheet_margin``: the least slack of the sheet over robot
    pairs, :math:`\\min_{i<j} (|\\mathbf{v}_i - \\mathbf{v}_j| - |\\mathbf{r}_i -
    \\mathbf{r}_j|)` (>= 0 for a formation that does not tear the sheet), m.
    """
    T = len(r.times)
    if T == 0:
        return {"beneath": [], "height_over_obstacle": [], "sheet_margin": []}
    hulls = shapely.convex_hull(shapely.multipoints(r.robots))
    beneath = np.zeros(T)
    for o in sc.world.obstacles:
        beneath = np.where(shapely.intersects(hulls, o.geometry),
                           np.maximum(beneath, o.height), beneath)
    over = np.where(beneath > 0, r.object[:, 2] - beneath, np.nan)
    V = sc.team.sheet.vertices
    iu, ju = np.triu_indices(V.shape[0], 1)
    slack = (np.linalg.norm(V[iu] - V[ju], axis=1)[None]
             - np.linalg.norm(r.robots[:, iu] - r.robots[:, ju], axis=2))

    def clean(a: np.ndarray) -> list[float | None]:
        return [float(x) if np.isfinite(x) else None for x in a]

    return {"beneath": clean(beneath), "height_over_obstacle": clean(over),
            "sheet_margin": clean(slack.min(axis=1))}


def _summary(sc: Scenario, r: PlanResult) -> dict[str, Any]:
    out = plan_to_dict(r)
    names = {f.name for f in dataclasses.fields(r)}
    why = getattr(r, "message") if "message" in names else r.reason   # convention, or older
    out.update(plan_series(sc, r), planner=r.planner, message=why or "plan verified",
               object_height=(None if r.formation is None
                              else float(r.formation.object_height)))
    return out


@dataclass
class _Job:
    scenario: Scenario
    stage: str = "queued"
    step: int = 0
    started: float = dc_field(default_factory=time.monotonic)
    finished: float | None = None
    result: dict[str, Any] | None = None
    error: str | None = None


class PlanAPI:
    """The planner viewer's endpoints; planning jobs run one at a time in a worker thread."""

    STEPS = 2                                  # baseline, then the crossing planner

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="taut-plan")
        self._jobs: dict[str, _Job] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def close(self) -> None:
        """Stop the worker (running jobs finish first)."""
        self._pool.shutdown(wait=False, cancel_futures=True)

    @staticmethod
    def _scenario(data: dict[str, Any]) -> Scenario:
        return plan_scenario_from_mapping(data)

    def load(self, body: dict[str, Any]) -> dict[str, Any]:
        """``{"example": name}``, an upload ``{"text", "filename"}`` or ``{"scenario":
        mapping}`` -> the validated scenario mapping and its geometry."""
        if "example" in body:
            data = self.catalog.mapping("plan", field(body, "example", str))
        elif "text" in body:
            data = mapping_from_upload(field(body, "text", str),
                                       field(body, "filename", str, default="upload.yaml"))
        else:
            data = field(body, "scenario", dict)
        sc = self._scenario(data)
        return {"scenario": plan_scenario_to_mapping(sc), "world": world_to_dict(sc)}

    def yaml(self, body: dict[str, Any]) -> dict[str, Any]:
        """The scenario as a YAML file that ``taut plan`` reads back."""
        sc = self._scenario(field(body, "scenario", dict))
        text = ("# planning scenario saved by `taut app`; read it back with: taut plan FILE\n"
                + yaml.safe_dump(plan_scenario_to_mapping(sc), sort_keys=False,
                                 default_flow_style=None))
        return {"yaml": text, "filename": "plan_scenario.yaml"}

    def run(self, body: dict[str, Any]) -> dict[str, Any]:
        """Start planning ``scenario``; returns ``{"job": id}`` to poll with :meth:`job`."""
        job = _Job(self._scenario(field(body, "scenario", dict)))
        with self._lock:
            jid = str(next(self._ids))
            self._jobs[jid] = job
            for old in list(self._jobs)[:-_KEEP_JOBS]:
                del self._jobs[old]
        self._pool.submit(self._work, job)
        return {"job": jid}

    def _work(self, job: _Job) -> None:
        sc = job.scenario
        try:
            job.stage, job.step = "bypass-only baseline", 1
            base = plan_baseline(sc)
            job.stage, job.step = "planner with obstacle crossing", 2
            best = plan(sc, time_budget=PLAN_TIME_CAP_S)
            job.result = {"plan": _summary(sc, best), "baseline": _summary(sc, base),
                          "world": world_to_dict(sc)}
        except TautError as exc:
            job.error = str(exc)
        except Exception as exc:               # never let a job take the server down
            job.error = f"planner: internal error ({exc.__class__.__name__})"
        finally:
            job.finished = time.monotonic()
            job.stage = "done"

    def job(self, jid: str) -> dict[str, Any]:
        """Progress of a job: ``state`` (running/done/error), ``stage``, ``step`` of
        ``steps``, ``elapsed`` s; the plans once done."""
        job = self._jobs.get(jid)
        if job is None:
            raise ScenarioError("job", f"no planning job {jid!r}")
        end = job.finished if job.finished is not None else time.monotonic()
        out: dict[str, Any] = {"stage": job.stage, "step": job.step, "steps": self.STEPS,
                               "elapsed": end - job.started}
        if job.finished is None:
            out["state"] = "running"
        elif job.error is not None:
            out.update(state="error", error=job.error)
        else:
            out.update(state="done", **(job.result or {}))
        return out

