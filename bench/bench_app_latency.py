"""Latency of the app: drag-to-redraw in the browser, and light requests while heavy
ones run.

Usage::

    python bench/bench_app_latency.py [--rounds 5] [--moves 60] [--json OUT]
    python bench/bench_app_latency.py --heavy [--rounds 5] [--json OUT]

``--heavy`` (no browser needed): ``taut app`` as its own process; each round first probes
the light requests (``GET /api/catalog`` and a static script) idle, then while heavy
requests run, all sent at once from their own threads (FK of a 1,000-robot team, a
15,000-step simulation of a 12-robot team whose JSON body is about 6 MB, and a 1.4 MB
YAML upload that parses for seconds before its 422), probes them again until the heavy
ones are done. The resident memory of the app and its worker processes together is
sampled between probes. Reports, per round and over all rounds, the median, 90th
percentile and maximum of the light requests idle and during, the heavy requests' own
times, the largest total resident memory sampled and each process's peak (``VmHWM``;
their sum bounds the total from above), and the load average.

Starts ``taut app`` as its own process on a free port (as a user runs it), opens it in
headless Chromium (Debian's chromium + chromium-driver, driven by Selenium) and, for
teams of N = 4 (regular square team), 8 (the FK paper's Example 2) and 20 (regular
20-gon team), drags robot 2 with real WebDriver pointer input (``--moves`` moves of 16
ms each). The page records, for every redraw, the time from the input event
(``event.timeStamp``) to the first animation frame after the SVG was updated
(``requestAnimationFrame``), conservatively: when drags arrive while a request is in
flight they are coalesced, and the time counts from the *oldest* event not yet drawn.
The first drag of each team is a discarded warm-up; teams are interleaved round by
round. Reports median, 90th percentile and maximum per N, the server's own FK time and
the machine's load average (this machine is shared: other work runs at the same time).
Needs the ``app-test`` extra and the Chromium packages.
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import numpy as np

from taut.app.browser import chromium, drag, find_browser, wait_for

ROOT = Path(__file__).resolve().parents[1]
TEAMS = {4: {"regular": 4}, 8: {"example": "example2_r2_r4_353mm.yaml"}, 20: {"regular": 20}}


def start_server() -> tuple[subprocess.Popen, str]:
    taut = Path(sys.executable).with_name("taut")
    proc = subprocess.Popen([str(taut), "app", "--port", "0"], stdout=subprocess.PIPE,
                            text=True, cwd=ROOT)
    line = proc.stdout.readline() if proc.stdout else ""
    if "serving on" not in line:
        proc.kill()
        raise SystemExit(f"taut app did not start: {line!r}")
    return proc, line.split("serving on ")[1].split()[0]


def one_drag(d, team: dict, moves: int) -> list[dict]:
    d.execute_script("SheetView.sc = null; window.tautLatency.length = 0;")
    d.execute_script("SheetView.load(arguments[0])", team)
    wait_for(d, "SheetView.sc && SheetView.fk && !SheetView.inflight")
    d.execute_script("window.tautLatency.length = 0")
    side = max(1, moves // 4)
    path = [(-1, 0)] * side + [(0, 1)] * side + [(1, 0)] * side + [(0, -1)] * side  # inwards first
    drag(d, '.robot[data-i="1"]', path)
    wait_for(d, "!SheetView.inflight && SheetView.pendingT0 === null")
    time.sleep(0.1)
    return d.execute_script("return window.tautLatency.slice()")


def summary(rows: list[dict]) -> dict:
    ms = sorted(r["ms"] for r in rows)
    q90 = ms[min(len(ms) - 1, int(round(0.9 * (len(ms) - 1))))]
    return {"redraws": len(ms), "median_ms": statistics.median(ms), "p90_ms": q90,
            "max_ms": ms[-1], "server_median_ms": statistics.median(r["server"] for r in rows),
            "network_median_ms": statistics.median(r["net"] for r in rows),
            "draw_median_ms": statistics.median(r["draw"] for r in rows),
            "wait_median_ms": statistics.median(r["wait"] for r in rows),
            "feasible_fraction": sum(bool(r["feasible"]) for r in rows) / len(rows),
            "under_50ms": sum(m < 50 for m in ms) / len(ms)}


def _get(port: int, token: str, method: str, path: str, body: bytes | None = None
         ) -> tuple[int, float]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=600)
    t0 = time.perf_counter()
    conn.request(method, path, body=body, headers={
        "Host": f"127.0.0.1:{port}", "X-Taut-Token": token,
        "Content-Type": "application/json"})
    resp = conn.getresponse()
    resp.read()
    conn.close()
    return resp.status, time.perf_counter() - t0


def heavy_bodies() -> dict[str, bytes]:
    """The issue's heavy requests: FK of 1,000 robots, a 15,000-step simulation (~6 MB),
    a 1.4 MB YAML upload (70,000 formation points for a 3-robot sheet: a 422 after the
    parse)."""
    from taut.app.catalog import regular_team
    from taut.sheet import Sheet

    sheet = Sheet.regular(1000, 1000.0)
    f = 0.8 * sheet.vertices + np.random.default_rng(0).uniform(-0.5, 0.5, (1000, 2))
    fk = {"sheet": np.round(sheet.vertices, 6).tolist(), "hold_height": 1000.0,
          "mass": 1.0, "formation": np.round(f, 6).tolist()}
    m = regular_team(12)
    wave = 30 * np.sin(2 * np.pi * np.arange(15000) / 400)
    path = [(np.array(m["formation"]) + w * np.array([1, 0.5])).round(9).tolist()
            for w in wave]
    sim = {"sheet": m["sheet"], "hold_height": m["hold_height"], "mass": 1.0,
           "formations": path}
    text = ("hold_height: 1000\nsheet: [[0, 0], [1000, 0], [0, 1000]]\nformation: ["
            + ", ".join(f"[{k}.5, {k}.25]" for k in range(70000)) + "]\n")
    return {"/api/sheet/fk": json.dumps(fk).encode(),
            "/api/sheet/simulate": json.dumps(sim).encode(),
            "/api/sheet/load": json.dumps({"text": text, "filename": "big.yaml"}).encode()}


#: The status each heavy request answers with.
HEAVY_STATUS = {"/api/sheet/fk": 200, "/api/sheet/simulate": 200, "/api/sheet/load": 422}


def _family(pid: int) -> list[int]:
    """``pid`` and its child processes (the app's workers)."""
    out = [pid]
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
    return out


def _status_kib(pid: int, key: str) -> int:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1])
    except OSError:
        pass
    return 0


def _rss_mib(pid: int) -> float:
    """Resident memory of the app and its workers together, MiB."""
    return sum(_status_kib(p, "VmRSS") for p in _family(pid)) / 1024


def _stats(ms: list[float]) -> dict:
    ms = sorted(ms)
    return {"n": len(ms), "median_ms": statistics.median(ms),
            "p90_ms": ms[min(len(ms) - 1, int(round(0.9 * (len(ms) - 1))))], "max_ms": ms[-1]}


def heavy_main(args: argparse.Namespace) -> int:
    """Light requests idle and during heavy ones (see the module docstring)."""
    proc, url = start_server()
    parsed = urlparse(url)
    port, token = parsed.port, parse_qs(parsed.query)["token"][0]
    bodies = heavy_bodies()
    light = ("/api/catalog", "/static/common.js")
    rounds = []
    load0 = os.getloadavg()
    try:
        for path in ("/api/sheet/fk", "/api/sheet/simulate"):  # compiled; discarded
            assert _get(port, token, "POST", path, bodies[path])[0] == 200
        for r in range(args.rounds):
            idle = [1e3 * _get(port, token, "GET", p)[1] for _ in range(15) for p in light]
            heavy: list[tuple[str, int, float]] = []

            def run(path: str, heavy: list = heavy) -> None:
                heavy.append((path, *_get(port, token, "POST", path, bodies[path])))

            threads = [threading.Thread(target=run, args=(p,)) for p in bodies]
            for t in threads:
                t.start()
            during, rss = [], [_rss_mib(proc.pid)]
            while any(t.is_alive() for t in threads):
                for p in light:
                    during.append(1e3 * _get(port, token, "GET", p)[1])
                rss.append(_rss_mib(proc.pid))
                time.sleep(0.02)
            for t in threads:
                t.join()
            assert all(st == HEAVY_STATUS[p] for p, st, _ in heavy), heavy
            rounds.append({"idle": idle, "during": during, "rss_max_mib": max(rss),
                           "heavy_s": {p: dt for p, _, dt in heavy}})
        peaks = {pid: _status_kib(pid, "VmHWM") / 1024 for pid in _family(proc.pid)}
    finally:
        proc.send_signal(2)
        proc.wait(30)
    load1 = os.getloadavg()
    print(f"light requests (catalog, static script) idle and during heavy ones; "
          f"{args.rounds} rounds; load average {load0[0]:.1f} -> {load1[0]:.1f} on "
          f"{os.cpu_count()} cores (shared machine)")
    print("round  idle median/p90/max ms    during n  median/p90/max ms    FK s  sim s "
          "YAML s  RSS MiB")
    for k, r in enumerate(rounds):
        i, d = _stats(r["idle"]), _stats(r["during"])
        hs = r["heavy_s"]
        print(f"{k:5d}  {i['median_ms']:6.1f} {i['p90_ms']:6.1f} {i['max_ms']:6.1f}"
              f"    {d['n']:8d}  {d['median_ms']:6.1f} {d['p90_ms']:6.1f} {d['max_ms']:6.1f}"
              f"  {hs['/api/sheet/fk']:5.1f}  {hs['/api/sheet/simulate']:5.1f}"
              f"  {hs['/api/sheet/load']:5.1f}  {r['rss_max_mib']:7.0f}")
    i = _stats([x for r in rounds for x in r["idle"]])
    d = _stats([x for r in rounds for x in r["during"]])
    print(f"  all  {i['median_ms']:6.1f} {i['p90_ms']:6.1f} {i['max_ms']:6.1f}"
          f"    {d['n']:8d}  {d['median_ms']:6.1f} {d['p90_ms']:6.1f} {d['max_ms']:6.1f}")
    print(f"peak resident memory per process (VmHWM, MiB; app first, then its workers "
          f"alive at the end): {', '.join(f'{v:.0f}' for v in peaks.values())}; sum "
          f"{sum(peaks.values()):.0f}")
    if args.json is not None:
        args.json.write_text(json.dumps({"load_average_before": load0,
                                         "load_average_after": load1, "rounds": rounds,
                                         "idle": i, "during": d,
                                         "peak_rss_mib": list(peaks.values())},
                                        indent=2) + "\n")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--moves", type=int, default=60)
    ap.add_argument("--heavy", action="store_true",
                    help="light requests while heavy ones run (no browser)")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    if args.heavy:
        return heavy_main(args)
    found = find_browser()
    if found is None:
        raise SystemExit("needs Chromium: apt-get install -y chromium chromium-driver")
    proc, url = start_server()
    load0 = os.getloadavg()
    samples: dict[int, list[dict]] = {n: [] for n in TEAMS}
    try:
        with chromium(*found) as d:
            d.get(url)
            wait_for(d, "document.body.dataset.ready")
            for n, team in TEAMS.items():                      # warm-up, discarded
                one_drag(d, team, args.moves)
            for r in range(args.rounds):
                order = list(TEAMS)[r % 3:] + list(TEAMS)[:r % 3]
                for n in order:
                    samples[n] += one_drag(d, TEAMS[n], args.moves)
    finally:
        proc.terminate()
        proc.wait(10)
    load1 = os.getloadavg()
    out = {"load_average_before": load0, "load_average_after": load1,
           "cores": os.cpu_count(), "results": {n: summary(s) for n, s in samples.items()}}
    print(f"drag-to-redraw latency, headless Chromium, {args.rounds} drags x {args.moves} "
          f"moves per team; load average {load0[0]:.1f} -> {load1[0]:.1f} on "
          f"{os.cpu_count()} cores (shared machine)")
    print(" N  redraws  median  p90    max   <50ms  server  network  draw  queued  FK-feasible")
    for n, s in out["results"].items():
        print(f"{n:2d}  {s['redraws']:7d}  {s['median_ms']:6.1f}  {s['p90_ms']:5.1f}  "
              f"{s['max_ms']:5.0f}  {100 * s['under_50ms']:4.0f}%  {s['server_median_ms']:6.1f}"
              f"  {s['network_median_ms']:7.1f}  {s['draw_median_ms']:5.1f}  "
              f"{s['wait_median_ms']:6.1f}  {100 * s['feasible_fraction']:5.0f}%")
    print("(times in ms: median of each stage; queued = input waited for a request in flight)")
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
