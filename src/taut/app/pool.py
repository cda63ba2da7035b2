"""The worker processes that compute the app's requests, seen from the server.

:class:`WorkerPool` keeps ``size`` worker processes (:mod:`taut.app.worker`, one request
at a time each) and hands a request's raw body to an idle one; the server's event loop
only moves bytes, so the page, its scripts, the catalog and job polls answer at once
while heavy requests are computed. A request is cancelled by killing its worker (a fresh
one is started in its place): when the client disconnects, when the request overruns its
time budget (HTTP 503) and when the app stops (Ctrl-C). A request whose client
disconnects while it still waits for a worker leaves the queue without reaching one.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import AsyncIterator, Awaitable, Callable, Coroutine
from pathlib import Path
from typing import Any

import anyio
import anyio.abc

from .worker import ASK, NO_BODY, REPLY, render

__all__ = ["WorkerPool", "default_size", "STARTUP_S", "MAX_WORKERS"]

#: Threads a worker's numerical libraries may use: parallelism comes from the pool.
_THREADS_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                "NUMBA_NUM_THREADS": "1"}
_CHUNK = 2**20
#: Longest wait for a fresh worker's imports (numba's cache included), s.
STARTUP_S = 120.0


#: Most worker processes by default. An idle worker holds about 0.2 GiB (its imports)
#: and one request may take it to :data:`taut.app.worker.MEMORY_LIMIT`, so the app of
#: one user stays near 1 GiB on any machine; its page keeps at most one request in flight
#: per view, and planning jobs run one at a time.
MAX_WORKERS = 2


def default_size() -> int:
    """Worker processes by default: one per core (of this process's CPU set), at most
    :data:`MAX_WORKERS`."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:                     # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(cores, MAX_WORKERS))


class _Died(Exception):
    """The worker process ended before replying."""


class _Gone(Exception):
    """The client disconnected before the reply."""


class _Worker:
    """One worker process and its pipes."""

    def __init__(self, process: anyio.abc.Process) -> None:
        self.process = process
        self.ready = False

    @classmethod
    async def start(cls, root: Path | None) -> _Worker:
        cmd = [sys.executable, "-m", "taut.app.worker", *([str(root)] if root else [])]
        process = await anyio.open_process(cmd, stdin=subprocess.PIPE,
                                           stdout=subprocess.PIPE, stderr=None,
                                           env=dict(os.environ, **_THREADS_ENV))
        return cls(process)

    async def _read(self, n: int) -> bytes:
        assert self.process.stdout is not None
        data = bytearray()
        try:
            while len(data) < n:
                data += await self.process.stdout.receive(min(_CHUNK, n - len(data)))
        except (anyio.EndOfStream, anyio.BrokenResourceError, anyio.ClosedResourceError):
            raise _Died from None
        return bytes(data)

    async def wait_ready(self) -> None:
        """Wait for the ready frame a fresh worker sends after its imports."""
        if not self.ready:
            await self._read(REPLY.size)
            self.ready = True

    async def ask(self, name: str, raw: bytes | None) -> tuple[int, bytes]:
        """Send one request, wait for its reply: ``(HTTP status, JSON bytes)``."""
        assert self.process.stdin is not None and self.ready
        key = name.encode()
        head = ASK.pack(len(key), NO_BODY if raw is None else len(raw)) + key
        try:
            await self.process.stdin.send(head if raw is None else head + raw)
        except (anyio.BrokenResourceError, anyio.ClosedResourceError, OSError):
            raise _Died from None
        status, length = REPLY.unpack(await self._read(REPLY.size))
        return status, await self._read(length)

    async def kill(self) -> None:
        """Stop the process now (its request is abandoned)."""
        with anyio.CancelScope(shield=True):
            with contextlib.suppress(ProcessLookupError):
                self.process.kill()
            await self.process.wait()
            await self.process.aclose()


async def _watch(receive: Callable[[], Awaitable[Any]], ask: Awaitable[tuple[int, bytes]]
                 ) -> tuple[int, bytes]:
    """``await ask``, unless the client disconnects first (raises :class:`_Gone`)."""
    result: tuple[int, bytes] | None = None

    async def watch(scope: anyio.CancelScope) -> None:
        while (await receive())["type"] != "http.disconnect":
            pass
        scope.cancel()

    async with anyio.create_task_group() as tg:
        tg.start_soon(watch, tg.cancel_scope)
        result = await ask
        tg.cancel_scope.cancel()
    if result is None:
        raise _Gone
    return result


class WorkerPool:
    """``size`` worker processes computing requests within ``budget_s`` each.

    Parameters
    ----------
    size : int
        Worker processes (requests computed at once); more requests wait their turn.
    budget_s : float
        Time budget of one request (its wait for a worker included), s.
    root : Path, optional
        The bundled examples' folder the workers' catalog reads.
    """

    def __init__(self, size: int, budget_s: float, root: Path | None) -> None:
        self.size, self.budget_s, self.root = size, budget_s, root
        self._idle: list[_Worker] = []
        self._slots = anyio.Semaphore(size)
        self._tasks: anyio.abc.TaskGroup | None = None

    @contextlib.asynccontextmanager
    async def running(self) -> AsyncIterator[WorkerPool]:
        """Start the workers; on exit cancel background jobs and kill every worker."""
        async with anyio.create_task_group() as tg:
            self._tasks = tg
            try:
                for _ in range(self.size - len(self._idle)):
                    self._idle.append(await _Worker.start(self.root))
                yield self
            finally:
                tg.cancel_scope.cancel()
                self._tasks = None
                idle, self._idle = self._idle, []
                for w in idle:
                    await w.kill()

    def pids(self) -> list[int]:
        """Process ids of the idle workers (the busy ones are not listed)."""
        return [w.process.pid for w in self._idle]

    def start_soon(self, job: Callable[..., Coroutine[Any, Any, Any]], *args: Any) -> None:
        """Run ``job(*args)`` in the background until the pool stops."""
        if self._tasks is None:
            raise RuntimeError("the worker pool is not running")
        self._tasks.start_soon(job, *args)

    async def call(self, name: str, raw: bytes | None, *,
                   receive: Callable[[], Awaitable[Any]] | None = None) -> tuple[int, bytes]:
        """Compute request ``name`` (``"sheet.fk"``, ...) on body ``raw`` in a worker:
        ``(HTTP status, JSON bytes)``. The budget counts from when a started worker takes
        the request (waiting for a free one and for a fresh one's imports, at most
        :data:`STARTUP_S`, do not count). With ``receive`` (the ASGI receive of the
        request) the request is dropped as soon as the client disconnects (status 499):
        while it waits for a worker it leaves the queue, while computing its worker is
        killed."""
        if receive is None:
            return await self._compute(name, raw)
        try:
            return await _watch(receive, self._compute(name, raw))
        except _Gone:
            return 499, render({"error": "request: the client disconnected"})

    async def _compute(self, name: str, raw: bytes | None) -> tuple[int, bytes]:
        """:meth:`call` without the watch on the client; a cancelled call kills its
        worker (whatever it was doing) and starts a fresh one in its place."""
        async with self._slots:
            worker = self._idle.pop() if self._idle else await _Worker.start(self.root)
            keep = False
            try:
                with anyio.fail_after(STARTUP_S):
                    await worker.wait_ready()
                with anyio.fail_after(self.budget_s):
                    status, data = await worker.ask(name, raw)
                keep = status != 507              # a worker out of memory is replaced
                return status, data
            except TimeoutError:
                what = (f"took longer than its {self.budget_s:g} s budget; try a smaller "
                        "input" if worker.ready else
                        f"no worker process started within {STARTUP_S:g} s")
                return 503, render({"error": f"request: {what}"})
            except _Died:
                return 500, render({"error": "internal error (the worker computing the "
                                             "request stopped); the server log has the "
                                             "details"})
            finally:
                if keep:
                    self._idle.append(worker)
                else:                              # killed whatever it was doing; replaced
                    await worker.kill()
                    with anyio.CancelScope(shield=True):
                        if self._tasks is not None:
                            self._idle.append(await _Worker.start(self.root))
