"""Forward-kinematics benchmark: taut against vvcm-rs and VVCM, one process, one run.

Usage::

    python bench/bench_fk.py [--quick] [--json OUT]

Measures, on this machine and in this process (peers from the ``bench`` extra; a peer
that is not installed is left out):

* per-call latency at N = 3, 4, 5, 6, 8, 10, 12, 15, 20, 30 of ``FKSolver.solve``,
  ``forward_kinematics`` (the validating wrapper), vvcm-rs (Rust, float32) and VVCM 1.0
  (C++/Eigen, float32) on random convex teams in mm (hold height 2 x sheet size) that
  hold the object (drawn again until taut finds a stable state: the case a user times;
  ``--any-team`` takes the first draw, held or not), and the ratio to the faster peer. The
  calls are *interleaved*: every repeat times a block of calls of each implementation in
  a shuffled order, so load from other processes hits all of them alike; the table
  gives the median over repeats (per-call times in CPU microseconds) and the spread
  (25th-75th percentile over repeats, relative). Peers whose one call would take more
  than ``--peer-budget`` seconds (its timed warm-up call) are not run at that N; a peer
  call over ``SLOW_CALL_S`` (N = 30) is timed on ``SLOW_REPEATS`` single calls (the
  "calls" column counts the timed peer calls);
* batch throughput at N = 4 and 8: ``FKSolver.solve_batch`` against a loop of each
  peer's calls over the same formations (interleaved repeats, CPU time; median and IQR
  over repeats), and the ratios, on perturbations of a team that holds the object and of
  one that does not. ``solve_batch`` is timed as a caller that reads ``success`` (the
  direct minimisation of formations without a stable state is then skipped away from a
  similar copy of the sheet); ``solve_batch, all read`` also reads every field (it runs
  that minimisation for every such formation: the cost before the batch was lazy);
* one N = 1000 call;
* agreement of the stable states with both peers and with the exhaustive method (the
  paper's Algorithm 1) on random convex and "scattered" teams.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

# The compiled solver is what is timed: a process would otherwise run the numpy engine
# while the kernel cache is cold (docs/compiled_kernels.md); this waits for the compiler.
os.environ.setdefault("TAUT_NUMBA", "always")

from taut.sheet import FKSolver, Sheet, forward_kinematics  # noqa: E402
from taut.sheet import random_scattered_team, random_team  # noqa: E402
from taut.sheet import SheetTeam  # noqa: E402

try:
    import vvcm_rs
except ImportError:  # pragma: no cover - optional
    vvcm_rs = None
try:
    import VVCM
except ImportError:  # pragma: no cover - optional
    VVCM = None

SIZES = (3, 4, 5, 6, 8, 10, 12, 15, 20, 30)
MM = 1000.0


def mm_team(n, rng, scattered=False):
    sheet, formation = (random_scattered_team if scattered else random_team)(n, rng)
    return Sheet(sheet.vertices * MM), formation * MM


#: Draws of :func:`held_team` before it gives up (a random convex team holds the object
#: about half the time at a hold height of 2 x the sheet size).
HELD_DRAWS = 100


def held_team(n, rng, any_team=False, held=True):
    """A random convex team in mm whose formation holds the object at a hold height of
    2 x the sheet size (the first draw when ``any_team``; one that does not hold it when
    not ``held``)."""
    for _ in range(HELD_DRAWS):
        sheet, formation = mm_team(n, rng)
        if any_team or forward_kinematics(SheetTeam(sheet, 2.0 * sheet.size),
                                          formation).success == held:
            return sheet, formation
    raise RuntimeError(f"no {'held' if held else 'unheld'} team of {n} robots in "
                       f"{HELD_DRAWS} draws")


class RsPeer:
    name = "vvcm-rs"

    def __init__(self, sheet, hold):
        self.engine = vvcm_rs.VvcmFk(float(hold), np.asarray(sheet.vertices, np.float32))

    def prepare(self, formation):
        return np.asarray(formation, np.float32)

    def call(self, f32):
        try:
            return self.engine.update_stable_solutions(f32)
        except vvcm_rs.VvcmError:
            return None

    def stable(self, formation):
        sols = self.call(self.prepare(formation))
        if sols is None:
            return []
        return [(tuple(int(i) for i in s.taut_cables), np.asarray(s.po, float))
                for s in sols.stable()]


class CppPeer:
    name = "VVCM"

    def __init__(self, sheet, hold):
        self.engine = VVCM.VVCM_FK(sheet.n, float(hold),
                                   np.asfortranarray(sheet.vertices, np.float32))

    def prepare(self, formation):
        return np.asfortranarray(formation, np.float32)

    def call(self, f32):
        return self.engine.update_stable_solutions(f32)

    def stable(self, formation):
        err = self.call(self.prepare(formation))
        if err != VVCM.VVCM_FK_Error.NoError:
            return []
        e = self.engine
        return [(tuple(int(i) - 1 for i in it), np.asarray(p, float))      # 1-based
                for it, p in zip(e.It, e.Po)]


def peers_for(sheet, hold):
    out = []
    if vvcm_rs is not None:
        out.append(RsPeer(sheet, hold))
    if VVCM is not None:
        out.append(CppPeer(sheet, hold))
    return out


def block_time(fn, arg, calls):
    """CPU seconds per call over ``calls`` calls."""
    start = time.process_time()
    for _ in range(calls):
        fn(arg)
    return (time.process_time() - start) / calls


def calibrate(fn, arg, target):
    """Number of calls that take about ``target`` CPU seconds (at least 1)."""
    one = block_time(fn, arg, 1)
    return max(1, int(target / max(one, 1e-7)))


def latency(n, rng, repeats, target, budget, last_peer_time, any_team=False):
    """Interleaved per-call times (us) of every implementation at team size ``n``."""
    sheet, formation = held_team(n, rng, any_team)
    hold = 2.0 * sheet.size
    team = SheetTeam(sheet, hold)
    solver = FKSolver(team)
    impls = {"solve": (solver.solve, formation),
             "forward_kinematics": (lambda R: forward_kinematics(team, R), formation)}
    slow: set[str] = set()
    for peer in peers_for(sheet, hold):
        arg = peer.prepare(formation)
        one = block_time(peer.call, arg, 1)          # warm-up call, timed
        if one > budget:
            last_peer_time[peer.name + "_skipped"] = one
            continue
        if one > SLOW_CALL_S:
            slow.add(peer.name)
        impls[peer.name] = (peer.call, arg)
    for k, (fn, arg) in impls.items():             # warm up: caches, first-call costs
        for _ in range(1 if k in slow else 3):
            fn(arg)
    calls = {k: 1 if k in slow else calibrate(*v, target) for k, v in impls.items()}
    times: dict[str, list[float]] = {k: [] for k in calls}
    order = list(calls)
    for r in range(repeats):
        rng.shuffle(order)
        for k in order:
            if k in slow and r >= SLOW_REPEATS:
                continue
            fn, arg = impls[k]
            times[k].append(block_time(fn, arg, calls[k]) * 1e6)
    for k in times:
        last_peer_time[k + "_calls"] = calls[k] * len(times[k])
    return {k: (float(np.median(v)), float(np.percentile(v, 25)), float(np.percentile(v, 75)))
            for k, v in times.items()}


#: A peer whose one call takes longer than this (CPU s; at N = 30 they take ~0.5-1.3 s)
#: is timed on ``SLOW_REPEATS`` single calls, interleaved with the first repeats.
SLOW_CALL_S = 0.2
SLOW_REPEATS = 5
#: Batch cases: (N, formations, perturbations of a team that holds the object). Without a
#: stable state ``solve_batch, all read`` runs the direct minimisation on every formation
#: (~2 ms each), hence the smaller batches; random convex teams of 5 or more robots at
#: this hold height nearly always hold the object (none of 100 draws at N = 5, 6, 8
#: failed to), so the teams that do not are of 3 and 4.
BATCHES = ((4, 20000, True), (8, 4000, True), (3, 1000, False), (4, 1000, False))


def feasible_perturbations(sheet, formation, batch, rng):
    forms = formation[None] + rng.normal(scale=0.002 * sheet.size, size=(batch, sheet.n, 2))
    d = np.linalg.norm(forms[:, :, None] - forms[:, None], axis=3)
    return np.ascontiguousarray(forms[np.all(d <= sheet.side_lengths(), axis=(1, 2))])


def read_all(res):
    """Every field of a batch result (what a caller reading all of it pays for)."""
    return (res.count, res.kind, res.object, res.tensions, res.success, res.status,
            res.message)


def throughput(n, batch, rng, repeats, any_team=False, held=True):
    """Formations per CPU second (median, 25th and 75th percentile over repeats) of each
    implementation, and the share of the formations that hold the object."""
    sheet, formation = held_team(n, rng, any_team, held)
    hold = 2.0 * sheet.size
    forms = feasible_perturbations(sheet, formation, batch, rng)
    solver = FKSolver(SheetTeam(sheet, hold))
    solver.solve_batch(forms[:2])
    peers = peers_for(sheet, hold)
    rows = {}
    prepared = {p.name: [p.prepare(f) for f in forms] for p in peers}

    def peer_loop(p):
        return lambda arg: [p.call(f) for f in arg]

    impls = {"solve_batch": (lambda arg: solver.solve_batch(arg).success, forms),
             "solve_batch, all read": (lambda arg: read_all(solver.solve_batch(arg)),
                                       forms),
             "solve loop": (lambda arg: [solver.solve(f) for f in arg], forms)}
    for p in peers:
        impls[p.name + " loop"] = (peer_loop(p), prepared[p.name])
    times: dict[str, list[float]] = {k: [] for k in impls}
    order = list(impls)
    for _ in range(repeats):
        rng.shuffle(order)
        for k in order:
            fn, arg = impls[k]
            times[k].append(block_time(fn, arg, 1))
    for k, v in times.items():
        rows[k] = tuple(len(forms) / float(np.percentile(v, q)) for q in (50, 75, 25))
    return len(forms), rows, float(solver.solve_batch(forms).success.mean())


def same_stable(a, b, size, tol=2e-3):
    """Same taut sets and object positions within ``tol`` x sheet size (float32 peers)."""
    if sorted(t for t, _ in a) != sorted(t for t, _ in b):
        return False
    pa = dict(a)
    return all(np.max(np.abs(pa[t] - p)) <= tol * size for t, p in b)


def agreement(teams, rng, scattered):
    counts = {"teams": 0, "vvcm-rs": 0, "VVCM": 0, "exhaustive": 0, "exhaustive_teams": 0,
              "peer_below_floor": 0}
    for k in range(teams):
        n = 3 + k % 10
        sheet, formation = mm_team(n, rng, scattered)
        hold = rng.uniform(0.4, 2.0) * sheet.size
        res = forward_kinematics(SheetTeam(sheet, hold), formation)
        ours = [(e.taut, e.object) for e in res.stable]
        counts["teams"] += 1
        for peer in peers_for(sheet, hold):
            theirs = peer.stable(formation)
            counts[peer.name] += same_stable(ours, theirs, sheet.size)
            counts["peer_below_floor"] += any(p[2] <= 0 for _, p in theirs)
        if n <= 10:
            exh = forward_kinematics(SheetTeam(sheet, hold), formation, method="exhaustive")
            counts["exhaustive_teams"] += 1
            counts["exhaustive"] += same_stable(ours, [(e.taut, e.object) for e in exh.stable],
                                                sheet.size, tol=1e-9)
    return counts


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats and teams")
    ap.add_argument("--peer-budget", type=float, default=20.0,
                    help="skip a peer whose single call would exceed this many seconds")
    ap.add_argument("--json", help="also write the results to this file")
    ap.add_argument("--any-team", action="store_true",
                    help="time the first random team of each size, held or not")
    args = ap.parse_args(argv)
    repeats, target = (5, 0.02) if args.quick else (11, 0.05)
    rng = np.random.default_rng(2026)
    print(f"peers: vvcm-rs {getattr(vvcm_rs, '__version__', 'not installed')}, "
          f"VVCM {'installed' if VVCM else 'not installed'}; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    print("per-call CPU time, median over interleaved repeats (IQR as +-% of median)")
    head = f"{'N':>3s} {'solve us':>14s} {'fk us':>14s} {'vvcm-rs us':>16s} {'VVCM us':>16s}"
    print(head + f" {'rs/solve':>9s} {'VVCM/solve':>10s} {'faster/solve':>12s} "
                 f"{'fk/solve':>9s} {'calls rs/VVCM':>13s}")
    report = {"latency": [], "batch": [], "agreement": {}}
    last: dict = {}
    for n in SIZES:
        t = latency(n, rng, repeats, target, args.peer_budget, last, args.any_team)

        def cell(key, width):
            if key not in t:
                skipped = last.get(key + "_skipped")
                txt = f"(>{skipped:.0f} s)" if skipped else "-"
                return f"{txt:>{width}s}"
            med, lo, hi = t[key]
            return f"{med:>{width - 6}.1f} +-{50 * (hi - lo) / med:>2.0f}%"

        def ratio(key):
            return f"{t[key][0] / t['solve'][0]:9.1f}" if key in t else f"{'-':>9s}"

        peer_times = [t[k][0] for k in ("vvcm-rs", "VVCM") if k in t]
        faster = (f"{min(peer_times) / t['solve'][0]:12.1f}" if peer_times
                  else f"{'-':>12s}")
        print(f"{n:3d} {cell('solve', 14)} {cell('forward_kinematics', 14)} "
              f"{cell('vvcm-rs', 16)} {cell('VVCM', 16)} {ratio('vvcm-rs')} "
              f"{ratio('VVCM'):>10s} {faster} {ratio('forward_kinematics')} "
              f"{last.get('vvcm-rs_calls', 0):>6d}/{last.get('VVCM_calls', 0):<6d}")
        for key in ("vvcm-rs_calls", "VVCM_calls"):
            last.pop(key, None)
        sys.stdout.flush()
        report["latency"].append({"N": n, **{k: v for k, v in t.items()}})
    sheet, formation = mm_team(1000, rng)
    start, cpu = time.perf_counter(), time.process_time()
    forward_kinematics(SheetTeam(sheet, 2.0 * sheet.size), formation)
    big, big_cpu = time.perf_counter() - start, time.process_time() - cpu
    print(f"N=1000: one forward_kinematics call {big_cpu:.2f} s CPU ({big:.2f} s wall)")
    report["n1000_s"] = {"cpu": big_cpu, "wall": big}
    print("\nbatch throughput (formations/s, CPU; median, IQR as +-% of median; every "
          "implementation on one thread):")
    for n, batch, held in BATCHES:
        count, rates, share = throughput(n, batch if not args.quick else batch // 4, rng,
                                         3 if args.quick else 5, args.any_team, held)
        peers = [k for k in rates if k.endswith(" loop") and k != "solve loop"]
        line = ", ".join(f"{k} {v[0]:,.0f} +-{50 * (v[2] - v[1]) / v[0]:.0f}%"
                         for k, v in rates.items())
        vs = "".join(f"; solve_batch = {rates['solve_batch'][0] / rates[k][0]:.1f}x the {k}"
                     for k in peers)
        what = "holds" if held else "does not hold"
        print(f"  N={n} ({count} formations of a team that {what} the object, "
              f"{100 * share:.0f}% held): {line}{vs}")
        report["batch"].append({"N": n, "formations": count, "held_share": share,
                                **{k: dict(zip(("median", "p25", "p75"), v))
                                   for k, v in rates.items()}})
    teams = 60 if args.quick else 200
    for label, scattered in (("random", False), ("scattered", True)):
        c = agreement(teams, rng, scattered)
        print(f"\nagreement on {c['teams']} {label} teams (N = 3..12; same stable taut sets, "
              f"positions within 2e-3 x size): vvcm-rs {c['vvcm-rs']}, VVCM {c['VVCM']}; "
              f"exhaustive {c['exhaustive']}/{c['exhaustive_teams']} (N <= 10, 1e-9 x size); "
              f"peer states at or below the floor: {c['peer_below_floor']}")
        report["agreement"][label] = c
    print(f"\nload average at the end {os.getloadavg()[0]:.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
