"""What the simulator's search for a step with a stable state costs, by how it reads the
batch (issue 25).

``simulate`` looks for the first step of a chunk where the object is held again
(``sim.simulate._recover``, via ``sim._branch.fk_stable_batch``) on a batch FK result. The
batch is lazy: reading ``kind`` (``.stable``) runs the direct minimisation of the lowest
state on every formation without a stable state; ``success`` runs it only next to a
similar copy of the sheet, the one place it can supply a stable state. This times both
reads on the same formations, interleaved in shuffled order over ``--repeats`` repeats
(CPU time per batch; median and 25th-75th percentile spread over repeats), on chunks of
``--chunk`` perturbed formations of random teams at N = 3..8, held at 0.15 x the sheet
size (so low that the object is on the floor: no stable state, the case ``_recover``
meets once the object was lost) and at 2 x (most formations hold it), and checks the two
reads give the same answer.

Usage: ``python bench/bench_sim_recover.py [--repeats 7] [--chunk 64] [--seed 5]``.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

os.environ.setdefault("TAUT_NUMBA", "always")

from taut.sheet import FKSolver, SheetTeam, random_team  # noqa: E402


def read_stable(solver: FKSolver, R: np.ndarray) -> np.ndarray:
    """The read before the fix: any stable slot per formation (forces every descent)."""
    return np.asarray(solver.solve_batch(R).stable.any(axis=1))


def read_success(solver: FKSolver, R: np.ndarray) -> np.ndarray:
    """The read after the fix (``fk_stable_batch``): the batch's ``success``."""
    return np.asarray(solver.solve_batch(R).success)


def formations(n: int, chunk: int, hold: float, rng: np.random.Generator
               ) -> tuple[SheetTeam, np.ndarray]:
    """A team held at ``hold`` x its size and ``chunk`` formations shrunk 0.5..0.95 about
    its centre and jittered by 1 % of the sheet size."""
    sheet, R0 = random_team(n, rng)
    c = R0.mean(axis=0)
    shrink = rng.uniform(0.5, 0.95, chunk)[:, None, None]
    R = c + shrink * (R0 - c) + 0.01 * sheet.size * rng.standard_normal((chunk, n, 2))
    return SheetTeam(sheet, hold * sheet.size), R


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--chunk", type=int, default=64)
    ap.add_argument("--seed", type=int, default=5)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    print(f"{'hold':>4} {'N':>3} {'held':>5} {'stable.any ms':>14} {'success ms':>11} {'ratio':>6}"
          "  spread (IQR/median) stable, success")
    for hold, n in [(h, n) for h in (0.15, 2.0) for n in range(3, 9)]:
        team, R = formations(n, args.chunk, hold, rng)
        solver = FKSolver(team)
        feasible = solver.solve_batch(R).feasible
        R = R[feasible]
        a, b = read_stable(solver, R), read_success(solver, R)      # warm-up, and agree
        assert np.array_equal(a, b), n
        times: dict[str, list[float]] = {"stable": [], "success": []}
        for _ in range(args.repeats):
            order = list(times)
            rng.shuffle(order)
            for name in order:
                fn = read_stable if name == "stable" else read_success
                t0 = time.process_time()
                fn(solver, R)
                times[name].append(time.process_time() - t0)
        med = {k: float(np.median(v)) for k, v in times.items()}
        spread = {k: (np.percentile(v, 75) - np.percentile(v, 25)) / med[k]
                  for k, v in times.items()}
        print(f"{hold:4.2f} {n:3d} {int(b.sum()):2d}/{len(R):<2d} {1e3 * med['stable']:14.2f} "
              f"{1e3 * med['success']:11.2f} {med['stable'] / med['success']:6.1f}"
              f"  {spread['stable']:.0%}, {spread['success']:.0%}")


if __name__ == "__main__":
    main()
