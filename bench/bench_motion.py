"""Benchmarks of inverse kinematics and quasi-static simulation (issue 3).

Prints markdown tables:

1. IK: time per target and round-trip success rate for N = 3..12 (targets = object and
   contact of a random stable FK state of a random team; success = forward kinematics of
   the IK formation has a stable all-taut equilibrium within 1e-6 of the sheet size).
2. Simulation steps/s at N = 4, 8, 20 on smooth trajectories (no events) and on
   key-frame trajectories with taut-set changes and jumps.
3. Optional (``pip install -e '.[bench]'``): agreement with vvcm-rs's
   ``VvcmManualSimulation`` (float32, mm, "closest stable solution" each step) on
   trajectories without jumps, and on the square-sheet jump scenario.

Usage: ``python bench/bench_motion.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from taut.errors import UnreachableTargetError
from taut.io.trajectory import load_trajectory
from taut.sheet import Sheet, forward_kinematics
from taut.sheet.ik import inverse_kinematics
from taut.sheet.random import random_team
from taut.sheet.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]


def stable_team(n, rng, **kw):
    while True:
        sheet, R = random_team(n, rng, **kw)
        fk = forward_kinematics(sheet, R, 1.0)
        if fk.stable:
            return sheet, R, fk


def smooth(R, T, amp=0.04):
    t = np.linspace(0, 1, T)
    ang = 3 * amp * np.sin(2 * np.pi * t)
    c, s = np.cos(ang), np.sin(ang)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    centre = R.mean(axis=0)
    shrink = 1 - amp * np.sin(np.pi * t) ** 2
    path = np.stack([t, 0.5 * np.sin(np.pi * t)], -1) * amp * 5
    return (np.einsum("tij,nj->tni", rot, R - centre) * shrink[:, None, None]
            + centre + path[:, None, :])


def keyframes(sheet, R0, rng, segments, steps, amp=0.25):
    keys = [R0]
    V = sheet.vertices
    iu, ju = np.triu_indices(len(R0), 1)
    for _ in range(segments):
        Q = keys[-1] + rng.normal(scale=amp, size=R0.shape)
        ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(Q[iu] - Q[ju], axis=1)
        c = Q.mean(axis=0)
        keys.append((Q - c) * min(1.0, 0.98 * ratio.min()) + c)
    s = np.linspace(0, 1, steps, endpoint=False)[:, None, None]
    return np.concatenate([(1 - s) * a + s * b for a, b in zip(keys[:-1], keys[1:])])


def bench_ik(per_n: int) -> None:
    rng = np.random.default_rng(2026)
    print("\n## Inverse kinematics (targets from stable FK states of random teams)\n")
    print("| N | targets | round trip ok | proved unreachable | not found | FK miss | median ms "
          "| max ms |")
    print("|---|---|---|---|---|---|---|---|")
    inverse_kinematics(Sheet.regular(4, 1.0), [0, 0, 0.5], 1.0)          # warm-up
    total = ok_total = 0
    for n in range(3, 13):
        times, ok, proved, unreachable, miss = [], 0, 0, 0, 0
        for _ in range(per_n):
            sheet, _, fk = stable_team(n, rng)
            e = fk.stable[int(rng.integers(len(fk.stable)))]
            t0 = time.perf_counter()
            try:
                r = inverse_kinematics(sheet, e.object, 1.0, contact=e.contact,
                                       heading=rng.uniform(-np.pi, np.pi))
            except UnreachableTargetError as exc:
                if "no all-taut formation exists" in str(exc):
                    proved += 1
                else:
                    unreachable += 1
                continue
            finally:
                times.append(time.perf_counter() - t0)
            back = forward_kinematics(sheet, r.formation, 1.0)
            hit = any(q.stable and len(q.taut) == n
                      and np.linalg.norm(q.object - e.object) <= 1e-6 * sheet.size
                      for q in back.equilibria)
            ok += hit
            miss += not hit
        total += per_n - proved
        ok_total += ok
        ms = 1e3 * np.array(times)
        print(f"| {n} | {per_n} | {ok} | {proved} | {unreachable} | {miss} | "
              f"{np.median(ms):.2f} | "
              f"{ms.max():.1f} |")
    print(f"\nOverall: {ok_total}/{total} = {100 * ok_total / total:.1f}% of the FK-derived "
          "targets not proved unreachable (proved unreachable: two robots' required "
          "horizontal distances from the object differ by more than the sheet lets them "
          "stand apart; not found: the search failed).")


def bench_sim(T: int) -> None:
    rng = np.random.default_rng(7)
    print("\n## Quasi-static simulation\n")
    print("| N | trajectory | steps | events | jumps | steps/s |")
    print("|---|---|---|---|---|---|")
    for n in (4, 8, 20):
        sheet, R0, _ = stable_team(n, rng, slack=(0.6, 0.8))
        for kind in ("smooth", "key frames"):
            if kind == "smooth":
                R = smooth(R0, T)
            else:
                R = keyframes(sheet, R0, rng, 5, max(T // 5, 2))
            simulate(sheet, R[:50], 1.0)                                    # warm-up
            t0 = time.perf_counter()
            res = simulate(sheet, R, 1.0)
            dt = time.perf_counter() - t0
            print(f"| {n} | {kind} | {len(R)} | {len(res.events)} | {len(res.jumps)} | "
                  f"{len(R) / dt:,.0f} |")


def bench_vvcm(T: int) -> None:
    try:
        import vvcm_rs
    except ImportError:
        print("\n(vvcm-rs not installed: pip install -e '.[bench]' for the comparison)")
        return
    print("\n## Agreement with vvcm-rs VvcmManualSimulation (float32, mm)\n")
    print("| N | steps | taut jumps | vvcm-rs no-solution steps | max |dp| mm | "
          "median |dp| mm | taut-set mismatches |")
    print("|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(11)
    for n in (4, 5, 6, 8):
        sheet, R0, _ = stable_team(n, rng, slack=(0.6, 0.8))
        R = smooth(R0, T)
        res = simulate(sheet, R, 1.0)
        mm = 1000.0
        sim = vvcm_rs.VvcmManualSimulation(1000.0, np.ascontiguousarray(
            sheet.vertices * mm, dtype=np.float32))
        sim.init(np.ascontiguousarray(R[0] * mm, dtype=np.float32),
                 np.ascontiguousarray(res.object[0] * mm, dtype=np.float32))
        theirs = np.full((len(R), 3), np.nan)
        mismatch = failures = 0
        for t in range(len(R)):
            try:
                theirs[t] = sim.get_new_stable_solution(
                    np.ascontiguousarray(R[t] * mm, dtype=np.float32))
            except vvcm_rs.VvcmError:
                failures += 1
                continue
            mismatch += tuple(int(i) for i in sim.taut_cables) != res.taut[t]
        d = np.linalg.norm(theirs - res.object * mm, axis=1)
        print(f"| {n} | {len(R)} | {len(res.jumps)} | {failures} | {np.nanmax(d):.3f} | "
              f"{np.nanmedian(d):.4f} | {mismatch} |")
    # The square-sheet jump: vvcm-rs picks the stable state closest to the last one.
    sheet = Sheet([[1, 1], [-1, 1], [-1, -1], [1, -1]])
    R = load_trajectory(ROOT / "examples/sheet/trajectories/square4_jump.csv").formations
    res = simulate(sheet, R, 1.5)
    sim = vvcm_rs.VvcmManualSimulation(1500.0, np.ascontiguousarray(sheet.vertices * 1000,
                                                                    dtype=np.float32))
    sim.init(np.ascontiguousarray(R[0] * 1000, dtype=np.float32),
             np.ascontiguousarray(res.object[0] * 1000, dtype=np.float32))
    theirs = np.array([sim.get_new_stable_solution(
        np.ascontiguousarray(f * 1000, dtype=np.float32)) for f in R])
    d = np.linalg.norm(theirs - res.object * 1000, axis=1)
    j = res.jumps[0]
    print(f"\nSquare-sheet jump scenario: taut jumps at step {j.step} "
          f"({j.taut_before} -> {j.taut_after}, drop {1000 * j.drop:.1f} mm); max |dp| "
          f"before it {d[:j.step].max():.3f} mm, after it {d[j.step:].max():.3f} mm.")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer targets and steps")
    args = ap.parse_args()
    bench_ik(8 if args.quick else 30)
    bench_sim(5000 if args.quick else 50000)
    bench_vvcm(500 if args.quick else 3000)


if __name__ == "__main__":
    main()
