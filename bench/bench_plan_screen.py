"""The linearised robustness screen of the planner's formation admission (issue 28).

Usage::

    python bench/bench_plan_screen.py [--count 50] [--seed 2024]

On ``count`` seeded scenarios (:func:`taut.plan.generate_suite`), plans every scenario with
the screen (:data:`taut.plan._options.LINEAR_SCREEN`) and without it, interleaved (the
order alternates), from cold memo caches, and reports:

* whether the plans are identical (status, times, robot positions);
* in the runs without the screen, how many candidates the admission
  (:func:`~taut.plan.formations._squeeze_robust.tolerates`) saw, how many the screen would
  have rejected, and whether the sampling rejects each of those too (a screen that rejects
  what the sampling accepts would change plans);
* plan times with and without (wall clock: report the load average).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from dataclasses import replace

import numpy as np

from bench_plan import timed           # from cold memo caches (bench/ is on the path)
from taut.plan import _options, generate_suite, plan
from taut.plan.formations import _squeeze_robust as sr


def ratios(state, z_min: float, max_shift: float) -> tuple[float, float, float]:
    """The linear prediction's margins in predicted standard deviations (as
    :func:`~taut.plan.formations._squeeze_robust.linear_rejects` computes them) and the
    taut margin in robot errors."""
    from taut.sheet import object_covariance
    acc = sr._tol.POSITION_ACCURACY
    cov = object_covariance(state, acc ** 2 / 4)
    s_z, s = np.sqrt(max(cov[2, 2], 0.0)), np.sqrt(max(np.trace(cov), 0.0))
    n = state.jacobian.shape[1]
    return ((state.height - z_min) / s_z, max_shift / s,
            state.taut_margin / (acc * np.sqrt(n)))


def same(a, b) -> bool:
    if a.status != b.status or a.success != b.success:
        return False
    if not a.success:
        return True
    return (np.array_equal(np.asarray(a.times), np.asarray(b.times))
            and np.array_equal(np.asarray(a.robots), np.asarray(b.robots)))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=50)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--start", type=int, default=0, help="skip the suite's first scenarios")
    args = ap.parse_args()
    on = _options.LINEAR_SCREEN
    off = replace(on, enabled=False)
    counts = {"calls": 0, "screened": 0, "sampling_also_rejects": 0, "sampling_rejects": 0}
    rejected: list[tuple[float, float, float]] = []   # linear ratios of what sampling rejects
    least = np.full(3, np.inf)                         # least ratios of what it accepts
    spent = {True: 0.0, False: 0.0}          # time inside the admission, s
    inner_tolerates, inner_rejects = sr.tolerates, sr.linear_rejects

    def audit_tolerates(solver, robots, state, z_min, max_shift=sr._tol.SQUEEZE_MAX_SHIFT,
                        draws=sr.LIBRARY_DRAWS):
        """In the runs without the screen: would it reject, and does the sampling?"""
        t = time.perf_counter()
        sampled = inner_tolerates(solver, robots, state, z_min, max_shift, draws)
        spent[_options.LINEAR_SCREEN.enabled] += time.perf_counter() - t
        if not _options.LINEAR_SCREEN.enabled:
            counts["calls"] += 1
            if inner_rejects(state, z_min, max_shift, on.sigmas):
                counts["screened"] += 1
                counts["sampling_also_rejects"] += not sampled
            if sampled:         # how close the screen may come: the least ratios accepted
                least[:] = np.fmin(least, ratios(state, z_min, max_shift))
            else:
                counts["sampling_rejects"] += 1
                rejected.append(ratios(state, z_min, max_shift))
                print("  sampling rejects a candidate; linear margins (sigmas): "
                      + " ".join(f"{x:.3g}" for x in rejected[-1]), flush=True)
        return sampled

    import taut.plan.formations._squeezed as sq
    import taut.plan.formations.library as lib
    sq.tolerates = lib.tolerates = audit_tolerates

    suite = generate_suite(args.count, args.seed)[args.start:]
    t_on, t_off, diff = [], [], []
    for i, sc in enumerate(suite):
        order = ((on, t_on), (off, t_off)) if i % 2 == 0 else ((off, t_off), (on, t_on))
        res = {}
        for screen, ts in order:
            _options.LINEAR_SCREEN = screen
            r, dt = timed(plan, sc)
            ts.append(dt)
            res[screen.enabled] = r
        if not same(res[True], res[False]):
            diff.append(sc.name)
        print(f"{sc.name:<16} {res[True].status:<18} on {t_on[-1]:.2f} s off {t_off[-1]:.2f} s;"
              f" so far: {counts}, admission time on {spent[True]:.1f} s off "
              f"{spent[False]:.1f} s, differ {diff}", flush=True)
    _options.LINEAR_SCREEN = on
    print()
    print(f"load average {os.getloadavg()}")
    print(f"plans identical with and without the screen: {len(suite) - len(diff)}/{len(suite)}"
          + (f" (differ: {', '.join(diff)})" if diff else ""))
    print(f"admission calls {counts['calls']}, screened out {counts['screened']} "
          f"({100 * counts['screened'] / max(counts['calls'], 1):.1f} %), sampling rejects "
          f"them too: {counts['sampling_also_rejects']}/{counts['screened']}")
    print("candidates the sampling rejects, (height - z_min) / s_z, max_shift / s, "
          "taut_margin / (accuracy sqrt(N)) (the screen rejects below its sigmas):")
    for r in rejected:
        print(f"  {r[0]:10.3g} {r[1]:10.3g} {r[2]:10.3g}")
    print("least ratios among the candidates the sampling accepts: "
          + " ".join(f"{x:.3g}" for x in least))
    print(f"time inside the admission: with screen {spent[True]:.1f} s, without "
          f"{spent[False]:.1f} s")
    print(f"plan time with screen: total {sum(t_on):.1f} s, median {statistics.median(t_on):.2f} s"
          f" (min {min(t_on):.2f}, max {max(t_on):.2f})")
    print(f"plan time without    : total {sum(t_off):.1f} s, median "
          f"{statistics.median(t_off):.2f} s (min {min(t_off):.2f}, max {max(t_off):.2f})")


if __name__ == "__main__":
    main()
