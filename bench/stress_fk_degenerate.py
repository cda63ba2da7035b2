"""Stress test of forward kinematics near the FK paper's Lemma 2 configuration.

A formation that is a similar copy of the sheet puts every lifted point on a 2-plane; a
formation a little away from one makes them nearly flat, where the taut set is decided by
a thickness float64 barely resolves. This script draws teams of regular N-gon sheets with
formations ``scale * V + noise`` (noise 1e-13..1e-7 of the sheet size, hold height high
enough that the object stays above the ground) and counts, per noise decade, the teams
whose forward kinematics has a stable state ("ok"), only unstable ones ("nostable") or
none ("none"). Every team here has a stable rest state physically.

Usage: ``python bench/stress_fk_degenerate.py [--teams 500] [--seed 3] [--n-min 4]
[--n-max 30]``.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from taut.errors import TautError
from taut.sheet import Sheet, forward_kinematics


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--teams", type=int, default=500)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--n-min", type=int, default=4)
    ap.add_argument("--n-max", type=int, default=30)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    counts: Counter = Counter()
    for _ in range(args.teams):
        n = int(rng.integers(args.n_min, args.n_max + 1))
        ang = np.arange(n) * 2 * np.pi / n
        V = np.column_stack([np.cos(ang), np.sin(ang)])
        noise = 10.0 ** rng.uniform(-13, -7)
        R = V * rng.uniform(0.3, 0.95) + rng.normal(scale=noise, size=V.shape)
        try:
            res = forward_kinematics(Sheet(V), R, rng.uniform(2, 6))
        except TautError:
            continue
        kind = "ok" if res.stable else ("nostable" if res.equilibria else "none")
        counts[(int(np.floor(np.log10(noise))), kind)] += 1
    print("noise decade   ok  nostable  none")
    for dec in sorted({d for d, _ in counts}):
        print(f"1e{dec:<4d}     {counts[(dec, 'ok')]:5d} {counts[(dec, 'nostable')]:9d} "
              f"{counts[(dec, 'none')]:5d}")


if __name__ == "__main__":
    main()
