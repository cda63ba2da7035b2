"""Throughput of `taut sweep` on the octagon stability map against the serial batched API.

Measures, on the same formations (FK paper Example 2 team, scale x stretch heading):
the plain batched API (``forward_kinematics_batch`` over the chunks, no sweep machinery),
the sweep run serially in-process (``workers=0``), and on a local Dask cluster with 1 and 2
worker processes (cluster start-up included, as a user sees it; and excluded, by timing a
run against a cluster started beforehand). Then the chunk size at 2 workers. Runs are
interleaved and repeated; medians and [min, max] are printed.

    python bench/bench_sweep.py [--points 20000] [--repeat 3]

``--memory N [N ...]`` instead measures the client's peak memory (``ru_maxrss`` of the
process that calls ``run_sweep``, workers excluded) and the throughput of the same map at
each size N with 2 local workers, one fresh process per size (interleaved over
``--repeat``), to check that the client's memory does not grow with the number of points.

``--trace N`` runs one sweep of N points (2 local workers) under ``tracemalloc`` and prints
the Python memory of the client's process (the local scheduler included) at every tenth
of the run, the growth per chunk between 30 % and 90 % and the source lines it comes from
(how issue 32's growth was traced to Dask's debugging logs; small ``--chunk`` values make
many chunks quickly).
"""

from __future__ import annotations

import argparse
import gc
import json
import logging
import resource
import subprocess
import sys
import statistics
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from taut.io import load_sheet_scenario
from taut.sweep.file import sweep_from_mapping
from taut.sheet import forward_kinematics_batch
from taut.sweep import run_sweep
from taut.sweep.points import chunk_bounds, expand, point_seeds
from taut.sweep.tasks.fk import transform_formations

ROOT = Path(__file__).resolve().parent.parent
BASE = ROOT / "examples" / "sheet" / "example2_r2_r4_353mm.yaml"


def spec_for(points: int, chunk: int):
    angles = 50
    scales = max(points // angles, 1)
    return sweep_from_mapping({
        "task": "fk_stability_map", "base": str(BASE), "chunk_size": chunk,
        "parameters": {"scale": {"range": [0.5, 1.0], "num": scales},
                       "stretch_angle": {"range": [0, 176.4], "num": angles},
                       "stretch": 1.3}})


def api_seconds(spec, chunk: int) -> float:
    sc = load_sheet_scenario(BASE)
    cols = expand(spec)
    params = {k: cols.get(k, np.full(spec.size, d)) for k, d in
              {"scale": 1.0, "stretch": 1.0, "stretch_angle": 0.0, "rotation": 0.0,
               "jitter": 0.0}.items()}
    forms = transform_formations(sc.formation, params, point_seeds(spec, cols["point"]))
    t0 = time.perf_counter()
    for lo, hi in chunk_bounds(spec.size, chunk):
        forward_kinematics_batch(sc.team, forms[lo:hi])
    return time.perf_counter() - t0


def sweep_seconds(spec, **kw) -> float:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = run_sweep(spec, Path(tmp) / "out", **kw)
        assert res.success, res.message
        return time.perf_counter() - t0


def summary(name: str, times: list[float], points: int, ref: float | None = None) -> str:
    med = statistics.median(times)
    rate = points / med
    extra = f"  {ref / med:5.2f}x API" if ref else ""
    per = f"  overhead {1e6 * (med - ref) / points:+7.1f} us/point" if ref else ""
    return (f"{name:<34} {med:7.2f} s [{min(times):.2f}, {max(times):.2f}]  "
            f"{rate:8.0f} points/s{extra}{per}")


def client_run(points: int, chunk: int) -> None:
    """One sweep with 2 local workers; prints this process's peak RSS and the wall time."""
    spec = spec_for(points, chunk)
    seconds = sweep_seconds(spec, workers=2)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024      # KiB -> MiB
    print(json.dumps({"points": spec.size, "seconds": seconds, "peak_rss_MiB": peak}))


def trace(points: int, chunk: int) -> None:
    """Python memory of this process along one 2-worker sweep (see the module docstring)."""
    spec = spec_for(points, chunk)
    marks, snaps = [k / 10 for k in range(1, 10)], {}

    def progress(done: int, total: int) -> None:
        if marks and done >= marks[0] * total:
            mark = marks.pop(0)
            gc.collect()
            now = tracemalloc.get_traced_memory()[0]
            print(f"{mark:4.0%} {done // chunk:6d} chunks  {now / 2**20:7.2f} MiB traced")
            if mark in (0.3, 0.9):
                snaps[mark] = (done, now, tracemalloc.take_snapshot())

    tracemalloc.start(1)
    with tempfile.TemporaryDirectory() as tmp:
        assert run_sweep(spec, Path(tmp) / "out", workers=2, progress=progress).success
    (d0, m0, s0), (d1, m1, s1) = snaps[0.3], snaps[0.9]
    n = (d1 - d0) / chunk
    print(f"30 % -> 90 %: {m1 - m0:+d} B over {n:.0f} chunks = {(m1 - m0) / n:+.0f} B a chunk")
    for stat in s1.compare_to(s0, "lineno")[:12]:
        print("  ", stat)


def memory(sizes: list[int], chunk: int, repeat: int) -> None:
    runs: dict[int, list[dict]] = {n: [] for n in sizes}
    for _ in range(repeat):                                   # interleaved
        for n in sizes:
            out = subprocess.run([sys.executable, __file__, "--client", str(n), "--chunk",
                                  str(chunk)], capture_output=True, text=True, check=True)
            runs[n].append(json.loads(out.stdout.strip().splitlines()[-1]))
    print(f"client peak RSS and throughput, 2 local workers, chunk {chunk}, {repeat} runs:")
    ref = None
    for n in sizes:
        rss = [r["peak_rss_MiB"] for r in runs[n]]
        rate = [r["points"] / r["seconds"] for r in runs[n]]
        ref = ref or statistics.median(rss)
        print(f"  {runs[n][0]['points']:>11,d} points: peak RSS {statistics.median(rss):7.1f} MiB "
              f"[{min(rss):.1f}, {max(rss):.1f}] ({statistics.median(rss) / ref:.2f}x the "
              f"smallest)  {statistics.median(rate):7.0f} points/s [{min(rate):.0f}, "
              f"{max(rate):.0f}]")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--chunk", type=int, default=2048)
    ap.add_argument("--memory", type=int, nargs="+", metavar="N")
    ap.add_argument("--trace", type=int, metavar="N")
    ap.add_argument("--client", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.trace:
        trace(args.trace, args.chunk)
        return
    if args.client:
        client_run(args.client, args.chunk)
        return
    if args.memory:
        memory(args.memory, args.chunk, args.repeat)
        return
    from distributed import Client, LocalCluster

    spec = spec_for(args.points, args.chunk)
    n = spec.size
    print(f"octagon stability map: {n} formations (N = 8), chunk {args.chunk}")
    runs: dict[str, list[float]] = {k: [] for k in
                                    ("api", "serial", "w1", "w2", "w2 warm")}
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster):
        addr = cluster.scheduler_address
        for _ in range(args.repeat):                     # interleaved
            runs["api"].append(api_seconds(spec, args.chunk))
            runs["serial"].append(sweep_seconds(spec, workers=0))
            runs["w1"].append(sweep_seconds(spec, workers=1))
            runs["w2"].append(sweep_seconds(spec, workers=2))
            runs["w2 warm"].append(sweep_seconds(spec, scheduler=addr))
        ref = statistics.median(runs["api"])
        print(summary("batched API (serial, no sweep)", runs["api"], n))
        print(summary("sweep, workers=0 (in process)", runs["serial"], n, ref))
        print(summary("sweep, 1 worker (cluster start incl.)", runs["w1"], n, ref))
        print(summary("sweep, 2 workers (cluster start incl.)", runs["w2"], n, ref))
        print(summary("sweep, 2 workers (running cluster)", runs["w2 warm"], n, ref))
        print("chunk size at 2 workers (running cluster):")
        for chunk in (128, 512, 2048, 8192):
            s = spec_for(args.points, chunk)
            times = [sweep_seconds(s, scheduler=addr) for _ in range(args.repeat)]
            print("  " + summary(f"chunk {chunk} ({-(-n // chunk)} tasks)", times, n, ref))


if __name__ == "__main__":
    main()
