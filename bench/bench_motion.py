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

from taut.io.trajectory import load_trajectory
from taut.sheet import Sheet, forward_kinematics
from taut.sheet import inverse_kinematics
from taut.sheet.ik._certificate import verify_certificate
from taut.sheet import random_team
from taut.sheet import simulate
from taut.sheet import SheetTeam

ROOT = Path(__file__).resolve().parents[1]


def stable_team(n, rng, **kw):
    while True:
        sheet, R = random_team(n, rng, **kw)
        fk = forward_kinematics(SheetTeam(sheet, 1.0), R)
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


def ik_targets(count: int, rng: np.random.Generator):
    """(sheet, object, contact, all_taut) of a random stable FK state of a random team,
    N = 3..12; ``all_taut``: the generating state had every cable taut, so its own formation
    is an answer and IK must not refuse it."""
    for _ in range(count):
        n = int(rng.integers(3, 13))
        sheet, _, fk = stable_team(n, rng)
        e = fk.stable[int(rng.integers(len(fk.stable)))]
        yield sheet, e.object, e.contact, len(e.taut) == n


def _check_ik(sheet, p, vo, r, all_taut: bool = False) -> str:
    """Independent check of one IK answer: 'verified', 'unreachable:<kind>',
    'budget_exhausted', or 'WRONG:<why>' (a success FK does not confirm, a certificate
    that does not re-check, or a refusal of a target whose own formation is an answer)."""
    if all_taut and not r.success:
        return "WRONG:refused-own-formation"
    if r.success:
        back = forward_kinematics(SheetTeam(sheet, 1.0), r.formation)
        hit = any(q.stable and len(q.taut) == sheet.n
                  and np.linalg.norm(q.object - p) <= 1e-6 * sheet.size
                  for q in back.equilibria)
        return "verified" if hit else "WRONG:fk"
    if r.status == "unreachable":
        s = sheet.size
        lengths = np.linalg.norm(sheet.vertices - vo, axis=1)
        d = 1.0 - p[2]
        with np.errstate(invalid="ignore"):
            rho = np.sqrt(lengths ** 2 - d ** 2) / s
        ok = r.certificate is not None and verify_certificate(
            r.certificate, (sheet.vertices - vo) / s, rho, d, lengths)
        return f"unreachable:{r.certificate.kind}" if ok else "WRONG:certificate"
    return r.status


def bench_ik(count: int, seed: int = 2026) -> None:
    rng = np.random.default_rng(seed)
    print(f"\n## Inverse kinematics on {count} targets from stable FK states of random teams "
          "(N = 3..12)\n")
    inverse_kinematics(SheetTeam(Sheet.regular(4, 1.0), 1.0), [0, 0, 0.5])     # warm-up
    outcome: dict[str, list[float]] = {}
    per_n: dict[int, dict[str, int]] = {}
    worst = (0.0, "")
    for sheet, p, vo, all_taut in ik_targets(count, rng):
        t0 = time.perf_counter()
        r = inverse_kinematics(SheetTeam(sheet, 1.0), p, contact=vo,
                               heading=rng.uniform(-np.pi, np.pi))
        dt = time.perf_counter() - t0
        key = _check_ik(sheet, p, vo, r, all_taut)
        worst = max(worst, (dt, f"N = {sheet.n}, {key}"))
        if key == "verified":
            key += f" ({r.construction})"
        outcome.setdefault(key, []).append(dt)
        row = per_n.setdefault(sheet.n, {})
        row[key.split(" ")[0]] = row.get(key.split(" ")[0], 0) + 1
    print("| outcome | targets | median ms | p90 ms | max ms |")
    print("|---|---|---|---|---|")
    for key, times in sorted(outcome.items()):
        ms = 1e3 * np.array(times)
        print(f"| {key} | {len(ms)} | {np.median(ms):.1f} | {np.percentile(ms, 90):.1f} | "
              f"{ms.max():.0f} |")
    print("\n| N | " + " | ".join(sorted({k for r in per_n.values() for k in r})) + " |")
    keys = sorted({k for r in per_n.values() for k in r})
    print("|---" * (len(keys) + 1) + "|")
    for n in sorted(per_n):
        print(f"| {n} | " + " | ".join(str(per_n[n].get(k, 0)) for k in keys) + " |")
    all_ms = 1e3 * np.concatenate([np.array(t) for t in outcome.values()])
    print(f"\nAll {len(all_ms)} targets (seed {seed}): median {np.median(all_ms):.1f} ms, "
          f"worst {worst[0]:.2f} s ({worst[1]}), total {all_ms.sum() / 1e3:.1f} s (machine "
          "shared with other work). 'WRONG' rows would be answers the independent re-check "
          "rejects.")


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
            team = SheetTeam(sheet, 1.0)
            simulate(team, R[:50])                                          # warm-up
            t0 = time.perf_counter()
            res = simulate(team, R)
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
        res = simulate(SheetTeam(sheet, 1.0), R)
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
    res = simulate(SheetTeam(sheet, 1.5), R)
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


def _peer_sims(n, V, R0, dt):
    """The peers' stateful simulators (float32, mm) or [] when not installed."""
    out = []
    try:
        import vvcm_rs
        out.append(("vvcm-rs", vvcm_rs.VvcmSimulation(
            1000.0, np.ascontiguousarray(V, np.float32), np.ascontiguousarray(R0, np.float32),
            dt=dt), np.ascontiguousarray))
    except ImportError:
        pass
    try:
        import VVCM
        out.append(("VVCM", VVCM.VVCM_Simulation(
            n, 1000.0, np.asfortranarray(V, np.float32), np.asfortranarray(R0, np.float32),
            dt=dt), np.asfortranarray))
    except ImportError:
        pass
    return out


def bench_step_rate(steps: dict[int, int], rounds: int) -> None:
    """Simulator.step vs the peers' VvcmSimulation / VVCM_Simulation.step on the same
    velocity-driven trajectories (mm, hold height 1000 mm), same process, interleaved."""
    from taut.sheet import Simulator
    rng = np.random.default_rng(5)
    dt = 0.01
    print("\n## Stateful simulation step rate (steps/s; median of interleaved rounds, "
          "[min..max])\n")
    print("| N | steps/round | taut Simulator | vvcm-rs | VVCM | taut/vvcm-rs | taut/VVCM |")
    print("|---|---|---|---|---|---|---|")
    for n, T in steps.items():
        sheet, R0, _ = stable_team(n, rng, slack=(0.6, 0.8))
        sheet = Sheet(sheet.vertices * 1000.0)
        path = smooth(R0 * 1000.0, rounds * T + 1)
        vel = np.diff(path, axis=0) / dt                       # (rounds*T, N, 2) mm/s
        V32 = sheet.vertices.astype(np.float32)
        ours = Simulator(SheetTeam(sheet, 1000.0), path[0], dt=dt)
        ours.step(velocities=vel[0])                # warm-up: loads the compiled code
        ours.step(formation=path[0])
        peers = _peer_sims(n, V32, path[0].astype(np.float32), dt)
        rates: dict[str, list[float]] = {"taut": []} | {name: [] for name, _, _ in peers}
        for k in range(rounds):
            block = vel[k * T:(k + 1) * T]
            t0 = time.perf_counter()
            for v in block:
                ours.step(velocities=v)
            rates["taut"].append(T / (time.perf_counter() - t0))
            for name, sim, order in peers:
                t0 = time.perf_counter()
                for v in block:
                    sim.set_velocity(order(v, dtype=np.float32))
                    sim.step()
                rates[name].append(T / (time.perf_counter() - t0))

        def cell(name):
            r = rates.get(name)
            if not r:
                return "n/a"
            return f"{np.median(r):,.0f} [{min(r):,.0f}..{max(r):,.0f}]"

        def ratio(name):
            r = rates.get(name)
            return f"{np.median(rates['taut']) / np.median(r):.2f}" if r else "n/a"
        print(f"| {n} | {T} | {cell('taut')} | {cell('vvcm-rs')} | {cell('VVCM')} | "
              f"{ratio('vvcm-rs')} | {ratio('VVCM')} |", flush=True)
    print("\nMachine shared with other work (load ~8-16 on 2 cores): absolute rates are "
          "low; ratios are measured in the same process, interleaved.")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer targets and steps")
    ap.add_argument("--ik-targets", type=int, default=1000, help="IK targets (default 1000)")
    ap.add_argument("--ik-seed", type=int, default=2026, help="IK target seed (default 2026)")
    ap.add_argument("--only", choices=["ik", "sim", "vvcm"], help="run one part")
    ap.add_argument("--steps-only", action="store_true", help="only the step-rate table")
    args = ap.parse_args()
    if args.steps_only:
        bench_step_rate({4: 300, 8: 30, 20: 3}, 3)
        return
    if args.only in (None, "ik"):
        bench_ik(80 if args.quick else args.ik_targets, args.ik_seed)
    if args.only == "ik":
        return
    if args.only in (None, "sim"):
        bench_step_rate({4: 300 if args.quick else 1000, 8: 30 if args.quick else 150,
                         20: 3 if args.quick else 8}, 3 if args.quick else 5)
    if args.only == "sim":
        return
    bench_sim(5000 if args.quick else 50000)
    bench_vvcm(500 if args.quick else 3000)


if __name__ == "__main__":
    main()
