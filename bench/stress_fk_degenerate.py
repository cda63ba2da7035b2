"""Stress test of forward kinematics near the FK paper's Lemma 2 configuration.

A formation that is a similar copy of the sheet puts every lifted point on a 2-plane; a
formation a little away from one makes them nearly flat, where the taut set is decided by
a thickness float64 barely resolves. This script draws teams of regular N-gon sheets with
formations ``scale * V + noise`` (noise 1e-13..1e-7 of the sheet size, hold height high
enough that the object stays above the ground) and counts, per noise decade, the teams
whose forward kinematics has a stable state ("ok"), only unstable ones ("nostable") or
none ("none"). Every team here has a stable rest state physically.

With ``--compare`` it also solves every team with ``method="subsets"`` and with the
numpy backend, and counts per decade the teams where "fast" and "subsets" (compiled) or
the compiled and numpy "fast" disagree on the stable taut sets, with the largest object
difference between agreeing answers (relative to the sheet size).

Usage: ``python bench/stress_fk_degenerate.py [--teams 500] [--seed 3] [--n-min 4]
[--n-max 30] [--compare]``.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from taut.errors import TautError
from taut.sheet import FKSolver, Sheet, forward_kinematics
from taut.sheet import SheetTeam


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--teams", type=int, default=500)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--n-min", type=int, default=4)
    ap.add_argument("--n-max", type=int, default=30)
    ap.add_argument("--compare", action="store_true")
    args = ap.parse_args()
    worst: Counter = Counter()
    rng = np.random.default_rng(args.seed)
    counts: Counter = Counter()
    for _ in range(args.teams):
        n = int(rng.integers(args.n_min, args.n_max + 1))
        ang = np.arange(n) * 2 * np.pi / n
        V = np.column_stack([np.cos(ang), np.sin(ang)])
        noise = 10.0 ** rng.uniform(-13, -7)
        R = V * rng.uniform(0.3, 0.95) + rng.normal(scale=noise, size=V.shape)
        try:
            res = forward_kinematics(SheetTeam(Sheet(V), rng.uniform(2, 6)), R)
        except TautError:
            continue
        kind = "ok" if res.stable else ("nostable" if res.equilibria else "none")
        dec = int(np.floor(np.log10(noise)))
        counts[(dec, kind)] += 1
        if args.compare:
            _compare(Sheet(V), R, res, dec, counts, worst)
    print("noise decade   ok  nostable  none" + ("  fast!=subsets  numba!=numpy  worst"
                                                   if args.compare else ""))
    for dec in sorted({d for d, _ in counts}):
        line = (f"1e{dec:<4d}     {counts[(dec, 'ok')]:5d} {counts[(dec, 'nostable')]:9d} "
                f"{counts[(dec, 'none')]:5d}")
        if args.compare:
            line += (f" {counts[(dec, 'methods')]:14d} {counts[(dec, 'backends')]:13d}"
                     f"  {worst[dec]:.1e}")
        print(line)


def _compare(sheet: Sheet, R: np.ndarray, res, dec: int, counts: Counter,
             worst: Counter) -> None:
    """Count disagreements of "subsets" and of the numpy backend with ``res``."""
    team = SheetTeam(sheet, res.hold_height)
    other = {"methods": FKSolver(team, method="subsets").solve(R),
             "backends": FKSolver(team, backend="numpy").solve(R)}
    for name, o in other.items():
        if [e.taut for e in o.stable] != [e.taut for e in res.stable]:
            counts[(dec, name)] += 1
            continue
        for a, b in zip(res.stable, o.stable):
            worst[dec] = max(worst[dec], float(np.abs(a.object - b.object).max()) / sheet.size)


if __name__ == "__main__":
    main()
