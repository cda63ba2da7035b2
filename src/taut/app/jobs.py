"""Planning jobs of the app: a bounded queue whose ids stay valid until fetched.

``POST /api/plan/run`` validates the scenario in a worker (a bad one is the request's
422), then queues a job; jobs run one at a time, each as two worker calls (the SE(2)
bypass baseline, then the planner with obstacle crossing; see
:class:`taut.app.plan_api.PlanAPI`), so the page can show which step is running. At
most ``max_jobs`` jobs are queued or running; one more gets HTTP 503 "busy". A job's id
answers ``GET /api/plan/job/<id>`` until the job has finished and its result been
fetched once. This module only keeps the table and splices the workers' JSON replies;
it computes nothing.
"""

from __future__ import annotations

import itertools
import json
import time
from dataclasses import dataclass, field as dc_field

import anyio

from .pool import WorkerPool
from .worker import render

__all__ = ["PlanJobs", "MAX_JOBS"]

#: Planning jobs queued or running at once; one more is refused as busy (HTTP 503).
MAX_JOBS = 4
#: Finished jobs not yet collected by the page that are kept (oldest dropped first);
#: queued and running jobs are never dropped.
_KEEP_JOBS = 16
#: The job's steps (worker calls) and what the page shows while each runs.
_STEPS = (("plan.baseline", "SE(2) bypass baseline"),
          ("plan.crossing", "planner with obstacle crossing"))


@dataclass
class _Job:
    stage: str = "queued"
    step: int = 0
    started: float = dc_field(default_factory=time.monotonic)
    finished: float | None = None
    parts: list[bytes] = dc_field(default_factory=list)   # the steps' JSON objects
    error: str | None = None


class PlanJobs:
    """The job table of one app (``max_jobs`` queued or running at most)."""

    def __init__(self, pool: WorkerPool, max_jobs: int = MAX_JOBS) -> None:
        self.pool, self.max_jobs = pool, max_jobs
        self._jobs: dict[str, _Job] = {}
        self._ids = itertools.count(1)
        self._turn = anyio.Lock()

    async def run(self, raw: bytes) -> tuple[int, bytes]:
        """Queue a job for the request body ``raw`` (``{"scenario": mapping}``):
        ``(status, JSON)`` with ``{"job": id}``, the scenario's 422 or 503 busy."""
        status, data = await self.pool.call("plan.check", raw)
        if status != 200:
            return status, data
        pending = sum(j.finished is None for j in self._jobs.values())
        if pending >= self.max_jobs:
            return 503, render({"error": f"plan: busy: {pending} planning jobs are queued "
                                         "or running; retry when one has finished"})
        jid, job = str(next(self._ids)), _Job()
        self._jobs[jid] = job
        done = [k for k, j in self._jobs.items() if j.finished is not None]
        for old in done[:max(0, len(done) - _KEEP_JOBS)]:
            del self._jobs[old]
        self.pool.start_soon(self._work, job, raw)
        return 200, render({"job": jid})

    async def _work(self, job: _Job, raw: bytes) -> None:
        try:
            async with self._turn:
                job.started = time.monotonic()
                for k, (name, stage) in enumerate(_STEPS, 1):
                    job.stage, job.step = stage, k
                    status, data = await self.pool.call(name, raw)
                    if status != 200:
                        job.error = str(json.loads(data)["error"])
                        break
                    job.parts.append(data)
        except anyio.get_cancelled_exc_class():
            job.error = "plan: the app stopped before the job finished"
            raise
        finally:
            job.finished = time.monotonic()
            job.stage = "done"

    def job(self, jid: str) -> tuple[int, bytes]:
        """Progress of a job: ``state`` (running/done/error), ``stage``, ``step`` of
        ``steps``, ``elapsed`` s; both plans and the world once done."""
        job = self._jobs.get(jid)
        if job is None:
            return 422, render({"error": f"job: no planning job {jid[:40]!r} (unknown, or "
                                         "its result was already fetched)"})
        if job.finished is not None:
            del self._jobs[jid]                   # fetched: the id is spent
        end = job.finished if job.finished is not None else time.monotonic()
        out = {"stage": job.stage, "step": job.step, "steps": len(_STEPS),
               "elapsed": end - job.started}
        if job.finished is None:
            return 200, render(dict(out, state="running"))
        if job.error is not None:
            return 200, render(dict(out, state="error", error=job.error))
        head = render(dict(out, state="done"))[:-1]
        return 200, b",".join([head, *(p[1:-1] for p in job.parts)]) + b"}"
