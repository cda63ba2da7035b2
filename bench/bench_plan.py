"""Planning benchmark: the paper's corridor and seeded cluttered-corridor suites.

Usage::

    python bench/bench_plan.py [--count 50] [--seed 2024] [--iterations 3000]
                               [--time-cap S] [--margin-study] [--robustness 5e-3]
                               [--trials 20] [--json OUT] [--library ompl-rrtconnect]

Every plan of the suites uses the deterministic budget (``iterations`` samples per
RRT-Connect run, seed 0), so which plans are found does not depend on the machine's load;
``--time-cap`` adds the optional wall-clock safety cap (off by default). Measures, on this
machine (report the load: the times are wall-clock):

* plan time of the planning paper's corridor (``examples/plan/paper_corridor.yaml``;
  goal < 2 s), median and spread of 5 runs, interleaved with the two baselines;
* on ``count`` seeded scenarios (:func:`taut.plan.generate_suite`, 3-8 robots): success of
  the crossing planner (SE(2) search), the SE(2) bypass baseline and the disc baseline;
  path length and time to the goal on the scenarios all three solve; plan times; the
  status of every failure (certificate or budget); that every crossing plan passes
  :func:`~taut.plan.verify_motion` re-run at 10x its sampling (:func:`resample_motion`);
  that the crossing planner succeeds on a superset of both baselines;
* ``--margin-study``: the crossing planner with ``sheet_margin=0`` too (path length and
  time against the default margin where both succeed);
* ``--robustness S``: per crossing plan, seeded Monte Carlo with every robot displaced up
  to ``S`` m (uniform in a disc) at every sample: tear and drop probabilities.
* ``--library NAME``: instead, the crossing planner with ``--search`` (default ``auto``)
  against the same planner searching with ``plan(..., search=NAME)`` (e.g. an OMPL
  planner, extra ``plan-ompl``), same validity checker, library, budget and seed,
  interleaved per scenario (the order alternates): success counts, plan times, who found
  each plan (the lattice, a sampling search, or a fallback), time to the goal where both
  succeed, and whether each succeeds on a superset of the other's scenarios.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from taut.io.plan_scenario import load_plan_scenario
from taut.plan import generate_suite, plan, plan_robustness, resample_motion, verify_motion

ROOT = Path(__file__).resolve().parent.parent


def timed(fn, *args, **kw):
    """Run ``fn`` from cold memo caches (the formation library and the memoised bypass
    search are shared between the planner and its baseline; each timed call pays for its
    own), and time it."""
    from taut.plan.formations import library
    from taut.plan import planner
    library._library.cache_clear()
    library._squeezed.cache_clear()
    planner._bypass.cache_clear()
    t = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t


def paper(budget: dict) -> None:
    sc = load_plan_scenario(ROOT / "examples" / "plan" / "paper_corridor.yaml")
    t = {"crossing": [], "se2-bypass": [], "disc": []}
    res = {}
    for _ in range(5):                                   # interleaved
        for name, kw in (("crossing", {}), ("se2-bypass", {"baseline": "se2"}),
                         ("disc", {"baseline": "disc"})):
            r, dt = timed(plan, sc, **budget, **kw)
            t[name].append(dt)
            res[name] = r
    for name, ts in t.items():
        r = res[name]
        print(f"paper corridor {name:<10}: median {statistics.median(ts):.2f} s "
              f"(min {min(ts):.2f}, max {max(ts):.2f}); {r.status}: {r.message[:90]}")


def row(sc, budget: dict, margin_study: bool, sigma: float | None, trials: int) -> dict:
    r, t_r = timed(plan, sc, **budget)
    b, t_b = timed(plan, sc, baseline="se2", **budget)
    d, t_d = timed(plan, sc, baseline="disc")
    out = dict(name=sc.name, n=sc.team.n, obstacles=len(sc.world.obstacles),
               ok=r.success, status=r.status, message=r.message, ok_se2=b.success,
               ok_disc=d.success, length=r.path_length, duration=r.duration,
               length_se2=b.path_length, duration_se2=b.duration,
               length_disc=d.path_length, duration_disc=d.duration, crossed=len(r.crossed),
               reforms=len(r.formations) - 1 if r.success else 0,
               plan_time=t_r, plan_time_se2=t_b, plan_time_disc=t_d, recheck=None,
               search=r.search, planner=r.planner,
               superset=bool(r.success or not (b.success or d.success)))
    if r.success:
        rr, ro = resample_motion(r.robots, r.object, 10)
        chk = verify_motion(sc, rr, ro, sheet_margin=r.sheet_margin)
        out["recheck"] = chk.success
        out["recheck_message"] = chk.message
        out["min_sheet_slack"] = r.verification.min_sheet_slack
        out["min_clearance"] = r.verification.min_clearance
        out["min_height_margin"] = r.verification.min_height_margin
        if sigma is not None:
            rob = plan_robustness(r, sigma, trials, seed=1)
            out.update(tear=rob.tear_probability, drop=rob.drop_probability,
                       contact=rob.contact_probability, collision=rob.collision_probability,
                       unsafe=rob.unsafe_probability, failure=rob.failure_probability,
                       worst_extension=rob.worst_extension,
                       worst_height_margin=rob.worst_height_margin,
                       worst_clearance=rob.worst_clearance, trials=trials)
    if margin_study:
        z, t_z = timed(plan, sc, sheet_margin=0.0, **budget)
        out.update(ok_m0=z.success, length_m0=z.path_length, duration_m0=z.duration,
                   plan_time_m0=t_z)
    return out


def report(rows: list[dict], margin_study: bool) -> bool:
    n = len(rows)
    print(f"\n{'planner':<11} {'success':>9} {'plan s':>7} {'IQR s':>11} {'max plan s':>10}")
    for label, ok, P in (("crossing", "ok", "plan_time"), ("se2-bypass", "ok_se2", "plan_time_se2"),
                         ("disc", "ok_disc", "plan_time_disc")):
        ts = [x[P] for x in rows]
        q1, q3 = np.percentile(ts, [25, 75])
        print(f"{label:<11} {sum(x[ok] for x in rows):>4}/{n:<4} {statistics.median(ts):>7.2f} "
              f"{q1:>5.2f}-{q3:<5.2f} {max(ts):>10.2f}")
    print("(plan s = median wall-clock per scenario, each call from cold caches)")
    for base, ok, L, D in (("se2-bypass", "ok_se2", "length_se2", "duration_se2"),
                           ("disc", "ok_disc", "length_disc", "duration_disc")):
        both = [x for x in rows if x["ok"] and x[ok]]
        if both:
            print(f"crossing vs {base} on the {len(both)} both solve: path "
                  f"{np.mean([x['length'] for x in both]):.3f} vs "
                  f"{np.mean([x[L] for x in both]):.3f} m, time "
                  f"{np.mean([x['duration'] for x in both]):.2f} vs "
                  f"{np.mean([x[D] for x in both]):.2f} s; crossing shorter on "
                  f"{sum(x['length'] < x[L] - 1e-9 for x in both)}, faster on "
                  f"{sum(x['duration'] < x[D] - 1e-9 for x in both)}")
    found = {}
    for x in rows:
        if x["ok"]:
            key = x.get("search") or x.get("planner")
            found[key] = found.get(key, 0) + 1
    print(f"crossing plans found by: {found}")
    sup_se2 = all(x["ok"] for x in rows if x["ok_se2"])
    sup_disc = all(x["ok"] for x in rows if x["ok_disc"])
    recheck = all(x["recheck"] for x in rows if x["ok"])
    fails = [x for x in rows if not x["ok"]]
    print(f"crossing superset of se2-bypass: {sup_se2}; of disc: {sup_disc}; every plan "
          f"passes the 10x re-check: {recheck}")
    print(f"plans crossing an obstacle: {sum(x['crossed'] > 0 for x in rows)}; with a "
          f"formation change: {sum(x['reforms'] > 0 for x in rows)}")
    for x in fails:
        print(f"  failed {x['name']}: {x['status']}: {x['message'][:160]}")
    if any("tear" in x for x in rows):
        rob = [x for x in rows if "tear" in x]
        print(f"robustness over {len(rob)} plans ({rob[0]['trials']} trials each): max "
              + ", ".join(f"{k} {max(x[k] for x in rob):.3f}"
                          for k in ("tear", "drop", "contact", "collision", "failure",
                                    "unsafe"))
              + f"; worst extension {max(x['worst_extension'] for x in rob) * 1e3:.1f} mm, "
              f"worst height margin {min(x['worst_height_margin'] for x in rob) * 1e3:.1f} "
              f"mm, worst clearance {min(x['worst_clearance'] for x in rob) * 1e3:.1f} mm")
    slack = [x["min_sheet_slack"] for x in rows if x["ok"]]
    if slack:
        print(f"least sheet slack over plans {min(slack) * 1e3:.2f} mm")
    if margin_study:
        both = [x for x in rows if x["ok"] and x["ok_m0"]]
        print(f"margin 0: success {sum(x['ok_m0'] for x in rows)}/{n}; on {len(both)} "
              f"solved by both: path {np.mean([x['length_m0'] for x in both]):.3f} m vs "
              f"{np.mean([x['length'] for x in both]):.3f} m, time "
              f"{np.mean([x['duration_m0'] for x in both]):.1f} s vs "
              f"{np.mean([x['duration'] for x in both]):.1f} s (margin 0 vs default)")
    return sup_se2 and sup_disc and recheck


def _dump(args, rows: list[dict], meta: dict, done: bool) -> None:
    n = len(rows)
    summary = {"scenarios": n, "finished": done,
               "crossing": sum(x["ok"] for x in rows),
               "se2_bypass": sum(x["ok_se2"] for x in rows),
               "disc": sum(x["ok_disc"] for x in rows),
               "superset_everywhere": all(x["superset"] for x in rows),
               "recheck_10x_all_pass": all(x["recheck"] for x in rows if x["ok"]),
               "statuses": {k: sum(x["status"] == k for x in rows)
                            for k in sorted({x["status"] for x in rows})},
               "load_now": os.getloadavg()}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"meta": meta, "summary": summary, "rows": rows},
                                    indent=1, default=float))


def compare_libraries(suite: list, library: str, budget: dict) -> bool:
    """``--library``: plan(search=<--search>) vs plan(search=``library``) on every
    scenario, interleaved (the order alternates), same budget and seed."""
    own = budget["search"]
    rows = []
    for k, sc in enumerate(suite):
        runs = {}
        order = (own, library) if k % 2 == 0 else (library, own)
        for name in order:
            r, dt = timed(plan, sc, **{**budget, "search": name})
            runs[name] = (r.success, r.search, dt, r.status, r.duration)
        rows.append(runs)
        print(f"{sc.name:<18} " + "  ".join(
            f"{n}: {runs[n][3]:<16} {str(runs[n][1]):<16} {runs[n][2]:5.1f} s"
            for n in (own, library)), flush=True)
    n = len(rows)
    print(f"\n{'search':<16} {'success':>9} {'median s':>9} {'IQR s':>11} {'max s':>6}")
    for name in (own, library):
        ts = [x[name][2] for x in rows]
        q1, q3 = np.percentile(ts, [25, 75])
        print(f"{name:<16} {sum(x[name][0] for x in rows):>4}/{n:<4} "
              f"{statistics.median(ts):>9.2f} {q1:>5.2f}-{q3:<5.2f} {max(ts):>6.2f}")
        found = {}
        for x in rows:
            if x[name][0]:
                found[x[name][1]] = found.get(x[name][1], 0) + 1
        print(f"  found by {found}")
    both = [x for x in rows if x[own][0] and x[library][0]]
    if both:
        print(f"time to the goal where both succeed ({len(both)}): "
              f"{np.mean([x[own][4] for x in both]):.2f} s ({own}) vs "
              f"{np.mean([x[library][4] for x in both]):.2f} s ({library})")
    own_sup = all(x[own][0] for x in rows if x[library][0])
    lib_sup = all(x[library][0] for x in rows if x[own][0])
    only_lib = sum(x[library][0] and not x[own][0] for x in rows)
    only_own = sum(x[own][0] and not x[library][0] for x in rows)
    print(f"{own} superset of {library}: {own_sup} ({only_lib} solved only by {library}); "
          f"{library} superset of {own}: {lib_sup} ({only_own} solved only by {own})")
    return own_sup


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=50)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--iterations", type=int, default=3000,
                    help="deterministic search budget: samples per RRT-Connect run")
    ap.add_argument("--time-cap", type=float, default=None,
                    help="optional wall-clock safety cap per search, s (default none)")
    ap.add_argument("--margin-study", action="store_true")
    ap.add_argument("--robustness", type=float, default=None, metavar="SIGMA")
    ap.add_argument("--trials", type=int, default=20)
    ap.add_argument("--no-paper", action="store_true")
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--search", default="auto", help="plan(search=...) of every run")
    ap.add_argument("--library", default=None, metavar="SEARCH",
                    help="compare the own RRT-Connect with plan(search=SEARCH), e.g. "
                         "ompl-rrtconnect")
    args = ap.parse_args(argv)
    budget = {"iterations": args.iterations, "time_budget": args.time_cap,
              "search": args.search}
    if args.library is not None:
        suite = generate_suite(args.count, args.seed)
        print(f"suite: {args.count} scenarios (seed {args.seed}); {args.iterations} "
              f"iterations, time cap {args.time_cap}; {args.search} vs {args.library}")
        return 0 if compare_libraries(suite, args.library, budget) else 1
    if not args.no_paper:
        paper(budget)
    meta = {"count": args.count, "seed": args.seed, "iterations": args.iterations,
            "search": args.search,
            "time_cap": args.time_cap, "robustness_sigma": args.robustness,
            "trials": args.trials, "margin_study": args.margin_study,
            "load_at_start": os.getloadavg(), "cpus": os.cpu_count(),
            "started": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())}
    suite, gen_time = timed(generate_suite, args.count, args.seed)
    print(f"\nsuite: {args.count} scenarios (seed {args.seed}, generated in {gen_time:.1f} s)")
    rows = []
    for sc in suite:
        rows.append(row(sc, budget, args.margin_study, args.robustness, args.trials))
        x = rows[-1]
        print(f"{x['name']:<18} {x['status']:<17} se2 {x['ok_se2']!s:<5} disc "
              f"{x['ok_disc']!s:<5} {x['plan_time']:.1f} s", flush=True)
        if args.json is not None:                    # partial results survive a stop
            _dump(args, rows, meta, done=False)
    good = report(rows, args.margin_study)
    if args.json is not None:
        _dump(args, rows, meta, done=True)
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
