"""The issue-25 property run at scale: the slow test's teams and checks, counted.

Imports ``draw_team`` and ``check_team`` from ``tests/sheet/fk/test_fk_edges_property.py``
so both draw the same teams from the same seeds (regular and random sheets, scaled /
rotated / shifted copies, noise 1e-13..1e-4, coordinates written to finite digits,
collinear and coincident robots, generic random teams) and check the same invariants: at
least one stable state where one must exist, no state reported twice, every method (the
exhaustive one where N <= 12), the numpy backend and the batch agree on the stable
positions, ``result.lowest`` reported (or the result says why not), and on every 5th seed
an independent SLSQP minimisation of the height.

Besides failures (by kind) it counts the teams where a merge of coinciding states
happened in any method, those where the direct minimisation supplied the lowest state
(any method or the batch), and the range of N. Progress is rewritten to ``--progress``
(JSON) every ``--every`` teams, so partial counts survive an interrupted run.

Usage: ``python bench/property_fk_teams.py [--start 0] [--teams 100000]
[--progress bench/results/property_fk_teams.json] [--every 200]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "sheet" / "fk"))

import taut.sheet.fk._batch_result as batch_mod  # noqa: E402
import taut.sheet.fk.results as results_mod  # noqa: E402
from test_fk_edges_property import (  # type: ignore[import-not-found]  # noqa: E402
    check_team, draw_team)

#: Failure kinds, by a phrase of check_team's message (first match wins).
KINDS = [("twice", "reported twice"), ("crash", "Error:"), ("no_lowest", "no lowest"),
         ("no_rest_claim", "says no rest state"), ("above_brute", "above the rest state"),
         ("read_first", "stable before the states were built"), ("batch", "batch"),
         ("status", "with status"), ("methods_disagree", " vs ")]


class _Events:
    """Counts merges and direct supplies made while one team is checked."""

    def __init__(self) -> None:
        self.merged = self.direct = 0
        merge, with_lowest = results_mod._merge_equilibria, results_mod._with_lowest

        def counted_merge(eqs: Any, *args: Any) -> Any:
            out = merge(eqs, *args)
            self.merged += len(out) < len(eqs)
            return out

        def counted_lowest(*args: Any) -> Any:
            out = with_lowest(*args)
            self.direct += bool(out[1])
            return out
        setattr(results_mod, "_merge_equilibria", counted_merge)    # counting wrappers
        setattr(batch_mod, "_merge_equilibria", counted_merge)
        setattr(results_mod, "_with_lowest", counted_lowest)


def _kind(failure: str) -> str:
    return next((k for k, phrase in KINDS if phrase in failure), "other")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--teams", type=int, default=100_000)
    ap.add_argument("--progress", type=Path,
                    default=ROOT / "bench" / "results" / "property_fk_teams.json")
    ap.add_argument("--every", type=int, default=200)
    args = ap.parse_args()
    events = _Events()
    counts: Counter = Counter()
    failures: list[str] = []
    n_range = [10**9, 0]
    t0 = time.perf_counter()
    for seed in range(args.start, args.start + args.teams):
        n = draw_team(seed)[0].n
        n_range = [min(n_range[0], n), max(n_range[1], n)]
        events.merged = events.direct = 0
        why = check_team(seed)
        counts["teams"] += 1
        counts["merged_teams"] += events.merged > 0
        counts["direct_teams"] += events.direct > 0
        if why is not None:
            counts["fail_" + _kind(why)] += 1
            failures.append(why)
        done = seed + 1 - args.start
        if done % args.every == 0 or done == args.teams:
            _write(args, counts, failures, n_range, time.perf_counter() - t0, seed)


def _write(args: argparse.Namespace, counts: Counter, failures: list[str],
           n_range: list[int], elapsed: float, last: int) -> None:
    """Rewrite the progress file (JSON; seconds, teams per second)."""
    report = {"start": args.start, "last_seed": last, "elapsed_s": round(elapsed, 1),
              "teams_per_s": round(counts["teams"] / elapsed, 2), "n_range": n_range,
              "counts": dict(counts), "failures": failures[:50]}
    tmp = args.progress.with_suffix(".tmp")
    tmp.write_text(json.dumps(report, indent=1))
    tmp.replace(args.progress)


if __name__ == "__main__":
    main()
