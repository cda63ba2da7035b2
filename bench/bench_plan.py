"""Planning benchmark: the paper's corridor and the seeded cluttered-corridor suite.

Usage::

    python bench/bench_plan.py [--count 50] [--seed 2024] [--json OUT]

Measures, on this machine:

* plan time of the planning paper's corridor scenario (``examples/plan/paper_corridor.yaml``;
  goal < 2 s), best of 5;
* on ``count`` seeded scenarios (:func:`taut.plan.generate_suite`, 3-8 robots): success
  rate, mean path length, mean time to the goal and mean plan time of the crossing planner
  and of the bypass-only baseline, overall and on the scenarios both solve;
* the issue's claims: the crossing planner succeeds on a superset of the baseline's
  scenarios and is never slower to the goal where both succeed (checked, reported).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from taut.io.plan_scenario import load_plan_scenario
from taut.plan import generate_suite, plan, verify_motion

ROOT = Path(__file__).resolve().parent.parent


def timed(fn, *args, **kw):
    t = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=50)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)

    paper = load_plan_scenario(ROOT / "examples" / "plan" / "paper_corridor.yaml")
    times = []
    for _ in range(5):
        r, dt = timed(plan, paper)
        times.append(dt)
    b = plan(paper, baseline=True)
    print(f"paper corridor: plan {min(times):.3f} s (best of 5; goal < 2 s), success "
          f"{r.success}, crossed {list(r.crossed)}, path {r.path_length:.2f} m, "
          f"{r.duration:.1f} s to goal; baseline success {b.success}")

    suite, gen_time = timed(generate_suite, args.count, args.seed)
    rows = []
    for sc in suite:
        res, t_res = timed(plan, sc)
        base, t_base = timed(plan, sc, baseline=True)
        for x in (res, base):
            if x.success and not verify_motion(sc, x.robots, x.object).ok:
                print(f"!! {sc.name}: returned plan fails re-verification", file=sys.stderr)
                return 1
        rows.append(dict(name=sc.name, n=sc.team.n, obstacles=len(sc.world.obstacles),
                         ok=res.success, ok_base=base.success,
                         length=res.path_length, length_base=base.path_length,
                         duration=res.duration, duration_base=base.duration,
                         crossed=len(res.crossed), plan_time=t_res, plan_time_base=t_base))

    def stats(sel, key):
        vals = [r[key] for r in rows if sel(r)]
        return (np.mean(vals) if vals else float("nan")), len(vals)

    n = len(rows)
    both = lambda r: r["ok"] and r["ok_base"]  # noqa: E731
    print(f"\nsuite: {n} scenarios (seed {args.seed}, generated in {gen_time:.1f} s)")
    header = f"{'planner':<10} {'success':>9} {'path m':>8} {'time s':>8} {'path m*':>8} " \
             f"{'time s*':>8} {'plan s':>7} {'max plan s':>10}"
    print(header)
    print("-" * len(header))
    for label, ok, L, D, P in (("crossing", "ok", "length", "duration", "plan_time"),
                               ("baseline", "ok_base", "length_base", "duration_base",
                                "plan_time_base")):
        succ = sum(r[ok] for r in rows)
        mL, _ = stats(lambda r: r[ok], L)
        mD, _ = stats(lambda r: r[ok], D)
        bL, _ = stats(both, L)
        bD, _ = stats(both, D)
        mP = np.mean([r[P] for r in rows])
        xP = np.max([r[P] for r in rows])
        print(f"{label:<10} {succ:>4}/{n:<4} {mL:>8.2f} {mD:>8.1f} {bL:>8.2f} {bD:>8.1f} "
              f"{mP:>7.2f} {xP:>10.2f}")
    print("(* = mean over the scenarios both planners solve)")
    superset = all(r["ok"] for r in rows if r["ok_base"])
    never_slower = all(r["duration"] <= r["duration_base"] * (1 + 1e-9) for r in rows if both(r))
    by_n = {k: (sum(r["ok"] for r in rows if r["n"] == k),
                sum(r["ok_base"] for r in rows if r["n"] == k),
                sum(1 for r in rows if r["n"] == k)) for k in range(3, 9)}
    print("by team size N: " + ", ".join(f"N={k}: {a}/{c} vs {b}/{c}"
                                          for k, (a, b, c) in by_n.items() if c))
    print(f"plans crossing at least one obstacle: {sum(r['crossed'] > 0 for r in rows)}")
    print(f"crossing succeeds on a superset of the baseline: {superset}; never slower where "
          f"both succeed: {never_slower}")
    if args.json is not None:
        args.json.write_text(json.dumps({"paper_plan_time": min(times), "rows": rows},
                                        indent=1, default=float))
    return 0 if superset and never_slower else 1


if __name__ == "__main__":
    sys.exit(main())
