"""Drag-to-redraw latency of the sheet explorer, measured in the browser.

Usage::

    python bench/bench_app_latency.py [--rounds 5] [--moves 60] [--json OUT]

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
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--moves", type=int, default=60)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
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
