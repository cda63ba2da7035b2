"""Running a sweep: serially in this process, on a local Dask cluster, or on an existing
one, with the same chunks and so the same rows.

Each chunk is evaluated by :func:`evaluate_chunk`, a pure function of the spec and the
chunk's bounds; the client writes each finished chunk once (as its future completes), so a
worker that dies mid-chunk only makes Dask recompute that chunk elsewhere: nothing is lost
or duplicated. The client keeps at most :data:`IN_FLIGHT_PER_WORKER` chunks per worker
thread submitted at a time and drops each result once written, and bounds the debugging
logs Dask keeps in its process (:data:`DASK_LOG_ENTRIES`, :data:`DASK_MONITOR_SAMPLES`), so
its memory does not grow with the number of points (measured in ``bench/bench_sweep.py
--memory``, traced with ``--trace``). What remains per chunk: the chunk bounds (~140 B a
chunk, 67 MB for 10^9 points in chunks of 2,048) and Dask's cache of task-key prefixes
(``dask.utils.key_split``, ~150 B a chunk, at most 100,000 keys).
"""

from __future__ import annotations

import logging
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._validate import as_array, as_count, as_flag, as_path, require_instance
from ..errors import SweepError, require_extra
from .file import base_model
from .points import chunk_bounds, chunk_streams, expand, point_seeds
from .registry import TASKS
from .spec import SweepSpec
from .store import Store
from .task import Columns

__all__ = ["SweepResult", "run_sweep", "evaluate_chunk", "chunk_size_of"]

#: Seconds to wait for an existing scheduler to answer before giving up.
CONNECT_TIMEOUT = 5.0
#: Chunks submitted but not yet written, per worker thread of the cluster (one running,
#: one queued so a worker never waits for the client).
IN_FLIGHT_PER_WORKER = 2
#: Entries Dask keeps in each of its debugging logs in the process running the sweep
#: (``distributed.admin.low-level-log-length``, default 1,000): the last messages of every
#: connection (a chunk's task spec, ~1-2 kB, per message), the scheduler's event topics
#: (an ``update-graph`` event per submitted chunk) and its transition log. A local
#: cluster's scheduler runs in this process, so at the default these grew the client by
#: ~10 kB a chunk over the first ~1,000 chunks (traced with tracemalloc; the "4 MiB a
#: million points" of the 10^7 run).
DASK_LOG_ENTRIES = 50
#: Samples the scheduler's system monitor keeps (``distributed.admin.system-monitor.
#: log-length``, default 7,200: an hour at its 0.5 s interval, ~10 series) for the
#: dashboard: 60 s here.
DASK_MONITOR_SAMPLES = 120
#: Most chunks one run may make (points over ``chunk_size``): each is a file, a checksum
#: and an entry in the run's chunk list (~100 bytes in memory); a 10^9-point sweep in
#: chunks of one point would have held 10^9 before any work.
MAX_CHUNKS = 1_000_000

_CONTEXTS: dict[str, Any] = {}


@dataclass(frozen=True)
class SweepResult:
    """What a sweep run did.

    Attributes
    ----------
    success : bool
        True when every requested point has a row in ``path``.
    status : {"ok", "interrupted"}
    message : str
    path : Path or None
        ``results.parquet`` (None when interrupted).
    rows : int
        Rows in ``path``.
    chunks_run, chunks_reused : int
        Chunks computed in this run / found finished in the folder.
    seconds : float
        Wall time of the run, s.
    damaged : tuple of (str, str)
        The chunks found in the folder but not finished, so computed again: ``(file name,
        why)`` with why ``"missing"``, ``"no checksum"``, ``"truncated"`` or ``"checksum
        mismatch"`` (:meth:`taut.sweep.store.Store.state`), in chunk order. Chunks never
        written are not listed (they are in ``chunks_run``).
    """

    success: bool
    status: str
    message: str
    path: Path | None
    rows: int
    chunks_run: int
    chunks_reused: int
    seconds: float
    damaged: tuple[tuple[str, str], ...] = ()


def chunk_size_of(spec: SweepSpec) -> int:
    """Points per chunk: the spec's, else the task's default."""
    require_instance(spec, SweepSpec, "spec")
    return int(spec.chunk_size) or TASKS[spec.task].default_chunk


def _context(spec: SweepSpec) -> Any:
    ctx = _CONTEXTS.get(spec.digest)
    if ctx is None:
        ctx = _CONTEXTS[spec.digest] = TASKS[spec.task].prepare(spec, base_model(spec))
    return ctx


def evaluate_chunk(spec: SweepSpec, start: int, stop: int,
                   params: Columns | None = None) -> Columns:
    """Rows ``start..stop-1`` of the sweep: ``point``, the parameters, the outputs.

    ``params`` (the chunk's parameter columns) may be passed in; by default they are
    expanded from the spec.
    """
    require_instance(spec, SweepSpec, "spec")
    start = as_count(start, "start", minimum=0, maximum=max(spec.size - 1, 0))
    stop = as_count(stop, "stop", minimum=start + 1, maximum=spec.size)
    n = stop - start
    if params is not None:
        require_instance(params, dict, "params")
        for name in ("point", *spec.names):
            if name not in params:
                raise SweepError("params", f"has no column {name!r}")
            as_array(params[name], f"params[{name!r}]", shape=(n,))
    task = TASKS[spec.task]
    ctx = _context(spec)
    cols = dict(params) if params is not None else expand(spec, start, stop)
    defaults = task.defaults(ctx)
    full = {name: np.asarray(cols[name], float) if name in cols
            else np.full(n, defaults[name], dtype=float) for name in task.parameters}
    seeds = point_seeds(spec, cols["point"])
    outputs = task.run(ctx, full, seeds)
    if spec.outputs:
        outputs = {k: outputs[k] for k in spec.outputs}
    row: Columns = {"point": np.asarray(cols["point"], np.int64)}
    row.update({name: np.asarray(cols[name], float) for name in spec.names})
    row.update(outputs)
    return row


def _connect(workers: int | None, scheduler: str | None) -> Any:
    """A client of ``scheduler``, else of a new local cluster, whose Dask logs in this
    process are bounded by :data:`DASK_LOG_ENTRIES` and :data:`DASK_MONITOR_SAMPLES` (each
    log's length is read when the scheduler, a connection or the client is created)."""
    require_extra("dask")
    require_extra("distributed")
    import dask

    with dask.config.set({"distributed.admin.low-level-log-length": DASK_LOG_ENTRIES,
                          "distributed.admin.system-monitor.log-length":
                              DASK_MONITOR_SAMPLES}):
        return _open_client(workers, scheduler)


def _open_client(workers: int | None, scheduler: str | None) -> Any:
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as exc:
            raise SweepError("scheduler", f"no Dask scheduler answers at {scheduler} within "
                             f"{CONNECT_TIMEOUT:g} s ({type(exc).__name__})") from None
    with warnings.catch_warnings():
        # Dask warns when its default HTTP port is taken; ":0" picks a free one anyway.
        warnings.simplefilter("ignore", UserWarning)
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR)
        return Client(cluster)


def run_sweep(spec: SweepSpec, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, limit: int | None = None,
              progress: Callable[[int, int], None] | None = None) -> SweepResult:
    r"""Run ``spec`` and write ``out/results.parquet``.

    Parameters
    ----------
    spec : SweepSpec
    out : path
        Results folder (see :class:`taut.sweep.store.Store`).
    workers : int, optional
        0: serial, in this process. Otherwise the number of worker processes of a local
        Dask cluster (default: one per CPU). Ignored with ``scheduler``.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://HOST:PORT``).
    resume : bool
        Continue an earlier run of the same sweep in ``out``, skipping finished chunks.
    limit : int, optional
        Only the first ``limit`` points (for quick checks); chunks stay those of the full
        sweep, so a later run with ``resume`` reuses them.
    progress : callable, optional
        ``progress(done_points, total_points)`` after each chunk.

    Returns
    -------
    SweepResult
        ``status="interrupted"`` when the run stopped early (Ctrl-C, a worker failing
        repeatedly); the chunks finished so far are kept for ``resume``.

    Examples
    --------
    A 3 x 2 stability map of a square team, run serially:

    >>> import tempfile, pathlib
    >>> from taut.sweep import read_results, sweep_from_mapping
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (tmp / "team.yaml").write_text(
    ...     "hold_height: 800\nsheet: [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]\n"
    ...     "formation: [[100, 100], [800, 50], [900, 850], [50, 700]]\n")
    >>> spec = sweep_from_mapping({"task": "fk_stability_map", "base": "team.yaml",
    ...                            "parameters": {"scale": [0.8, 0.9, 1.0],
    ...                                           "stretch": [1.0, 1.1]}}, root=tmp)
    >>> run_sweep(spec, tmp / "out", workers=0).rows
    6
    >>> columns, meta = read_results(tmp / "out")
    >>> columns["scale"].tolist(), meta["sweep_task"]
    ([0.8, 0.8, 0.9, 0.9, 1.0, 1.0], 'fk_stability_map')
    """
    require_instance(spec, SweepSpec, "spec")
    out = as_path(out, "out")
    resume = as_flag(resume, "resume")
    if limit is not None:
        limit = as_count(limit, "limit", minimum=1)
    t0 = time.perf_counter()
    total = spec.size if limit is None else min(int(limit), spec.size)
    if total < 1:
        raise SweepError("limit" if limit is not None else "parameters", "selects no points")
    size = chunk_size_of(spec)
    chunks = -(-total // size)
    if chunks > MAX_CHUNKS:
        raise SweepError("chunk_size", f"{total} points in chunks of {size} make {chunks} "
                         f"chunks, more than {MAX_CHUNKS}; use a chunk_size of at least "
                         f"{-(-total // MAX_CHUNKS)}")
    with Store(out, spec.digest, resume=resume) as store:
        return _run(spec, store, limit, total, workers, scheduler, progress, t0)


def _run(spec: SweepSpec, store: Store, limit: int | None, total: int,
         workers: int | None, scheduler: str | None, progress: Any,
         t0: float) -> SweepResult:
    bounds = chunk_bounds(spec.size, chunk_size_of(spec), stop=total)
    stored = [store.state(k) for k in range(len(bounds))]
    todo = [st != "finished" for st in stored]
    damaged = tuple((store.chunk_path(k).name, st) for k, st in enumerate(stored)
                    if st not in ("finished", "not computed"))
    n_todo = sum(todo)
    done = sum(min(hi, total) - lo for (lo, hi), run in zip(bounds, todo) if not run)
    try:
        for k, cols in _execute(spec, bounds, todo, workers, scheduler):
            store.write_chunk(k, cols)
            done += min(bounds[k][1], total) - bounds[k][0]
            if progress is not None:
                progress(done, total)
    except (KeyboardInterrupt, _WorkerFailure) as exc:
        msg = "interrupted" if isinstance(exc, KeyboardInterrupt) else str(exc)
        return SweepResult(False, "interrupted", f"{msg}: {done} of {total} points done; run "
                           "again with --resume to continue", None, 0, n_todo,
                           len(bounds) - n_todo, time.perf_counter() - t0, damaged)
    meta = {"taut_version": __version__, "sweep_digest": spec.digest,
            "sweep_task": spec.task, "sweep_source": spec.source}
    path = store.assemble(len(bounds), total, meta)
    return SweepResult(True, "ok", f"{total} points", path, total, n_todo,
                       len(bounds) - n_todo, time.perf_counter() - t0, damaged)


class _WorkerFailure(Exception):
    """A chunk failed on the cluster (e.g. its workers kept dying)."""


def _evaluate_part(spec: SweepSpec, start: int, stop: int,
                   states: tuple[Mapping[str, Any], ...] | None) -> Columns:
    """:func:`evaluate_chunk` of a chunk whose random columns are drawn from ``states``
    (:func:`~taut.sweep.points.chunk_streams`): a task carries the spec and a few hundred
    bytes, never the chunk's columns, so the scheduler holds no data per chunk."""
    return evaluate_chunk(spec, start, stop, expand(spec, start, stop, states))


def _execute(spec: SweepSpec, bounds: list[tuple[int, int]], todo: list[bool],
             workers: int | None, scheduler: str | None) -> Any:
    """Yield ``(chunk index, columns)`` as chunks finish (chunks ``k`` with ``todo[k]``)."""
    if not any(todo):
        return
    pending = ((k, lo, hi, states) for k, ((lo, hi), states)
               in enumerate(zip(bounds, chunk_streams(spec, bounds))) if todo[k])
    if workers == 0 and scheduler is None:
        for k, lo, hi, states in pending:
            yield k, _evaluate_part(spec, lo, hi, states)
        return
    client = _connect(workers, scheduler)          # first: a missing extra is named
    from distributed import as_completed
    try:
        index: dict[str, int] = {}
        # The spec goes to the workers once; a task names it. Sent with every task, a
        # grid's value arrays (their size grows with the sweep) would pass through the
        # scheduler, which keeps recent task graphs, once per chunk.
        shared = client.scatter(spec, broadcast=True, hash=False)

        def submit() -> Any:
            item = next(pending, None)
            if item is None:
                return None
            k, lo, hi, states = item
            fut = client.submit(_evaluate_part, shared, lo, hi, states,
                                key=f"taut-sweep-{spec.digest[:16]}-{k}", pure=False)
            index[fut.key] = k
            return fut

        window = IN_FLIGHT_PER_WORKER * max(sum(client.nthreads().values()), 1)
        first = [f for f in (submit() for _ in range(window)) if f is not None]
        running = as_completed(first)
        del first
        for fut in running:
            try:
                cols = fut.result()
            except Exception as exc:   # a task error travels back from the worker
                from ..errors import TautError
                if isinstance(exc, TautError):
                    raise
                raise _WorkerFailure(f"chunk {index[fut.key]} failed on the cluster "
                                     f"({type(exc).__name__}: {exc})") from None
            k = index.pop(fut.key)
            fut.release()                       # the cluster may forget it now
            nxt = submit()
            if nxt is not None:
                running.add(nxt)
            yield k, cols
    finally:
        cluster = getattr(client, "cluster", None)
        client.close()
        if cluster is not None and scheduler is None:
            cluster.close()
