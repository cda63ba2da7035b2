"""JSON endpoints of the planner viewer: load a planning scenario, run the planner and its
SE(2) bypass baseline (the same search with crossing disabled) in a background job (the
page polls its progress), and return both plans with the series the page plots.

Planning is :func:`taut.plan.plan` (``baseline="se2"`` for the baseline) and the series
are :func:`taut.plan.plan_profile`; this module computes nothing itself, it only reshapes
their results for drawing. Lengths m, times s.
"""

from __future__ import annotations

import itertools
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field as dc_field
from typing import Any

import numpy as np
import yaml

from ..io.serialize import json_ready, plan_to_dict
from ..errors import ScenarioError, TautError
from ..io import plan_scenario_from_mapping, plan_scenario_to_mapping
from ..plan import PlanResult, Scenario, plan, plan_profile
from .catalog import Catalog
from .payload import field, mapping_from_upload

__all__ = ["PlanAPI", "BusyError", "plan_series", "world_to_dict", "MAX_JOBS"]

#: Planning jobs queued or running at once; one more is refused as busy (HTTP 503).
MAX_JOBS = 4
#: Finished jobs not yet collected by the page that are kept (oldest dropped first);
#: queued and running jobs are never dropped.
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


def plan_series(r: PlanResult) -> dict[str, list[float | None]]:
    """Per-sample series of a plan for the viewer's plots: the fields of its
    :func:`taut.plan.plan_profile` (null where not finite): ``beneath_height_m``,
    ``height_over_obstacle_m`` and ``sheet_slack_m``."""
    p = plan_profile(r)
    return {"beneath_height_m": json_ready(p.beneath_height_m),
            "height_over_obstacle_m": json_ready(p.height_over_obstacle_m),
            "sheet_slack_m": json_ready(p.sheet_slack_m)}


def _summary(r: PlanResult) -> dict[str, Any]:
    out = plan_to_dict(r)
    out.update(plan_series(r), object_height=(None if r.formation is None
                                              else float(r.formation.object_height)))
    return out


class BusyError(TautError):
    """The planner's queue is full (the server answers HTTP 503); retry later."""


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
    """The planner viewer's endpoints; planning jobs run one at a time in a worker thread,
    at most ``max_jobs`` queued or running. A job's id stays valid until the job has
    finished and its result been fetched once by :meth:`job`."""

    STEPS = 2                                  # baseline, then the crossing planner

    def __init__(self, catalog: Catalog, max_jobs: int = MAX_JOBS) -> None:
        self.catalog = catalog
        self.max_jobs = max_jobs
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
            pending = sum(j.finished is None for j in self._jobs.values())
            if pending >= self.max_jobs:
                raise BusyError("plan", f"busy: {pending} planning jobs are queued or "
                                        "running; retry when one has finished")
            jid = str(next(self._ids))
            self._jobs[jid] = job
            done = [k for k, j in self._jobs.items() if j.finished is not None]
            for old in done[:max(0, len(done) - _KEEP_JOBS)]:
                del self._jobs[old]
        self._pool.submit(self._work, job)
        return {"job": jid}

    def _work(self, job: _Job) -> None:
        sc = job.scenario
        try:
            job.started = time.monotonic()
            job.stage, job.step = "SE(2) bypass baseline", 1
            base = plan(sc, baseline="se2", time_budget=PLAN_TIME_CAP_S)
            job.stage, job.step = "planner with obstacle crossing", 2
            best = plan(sc, time_budget=PLAN_TIME_CAP_S)
            job.result = {"plan": _summary(best), "baseline": _summary(base),
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
        with self._lock:
            job = self._jobs.get(jid)
            if job is not None and job.finished is not None:
                del self._jobs[jid]               # fetched: the id is spent
        if job is None:
            raise ScenarioError("job", f"no planning job {jid[:40]!r} (unknown, or its "
                                       "result was already fetched)")
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

