"""Forward kinematics of two source trees timed in one run, against both peers.

Answers "did a change cost the hot path?" without comparing runs made at different times
(on a shared machine the load changes more between runs than a few percent). Each tree is
timed in its own child process (``PYTHONPATH`` set to the tree's ``src``); the children
alternate (A, B, B, A, A, B, ...) for ``--repeats`` rounds, and every child also times
vvcm-rs and VVCM (the ``bench`` extra) on the same teams, so each tree gets a ratio to
both peers measured in the same process, seconds apart.

Per child: per-call CPU time (median of 5 blocks of ~0.2 s) of ``FKSolver.solve``, of
``solve`` followed by ``.stable`` (states built, merged where they coincide) and of each
peer's ``update_stable_solutions`` (up to ``PEER_MAX_N``), at N = 3, 4, 5, 6, 8, 10, 12, 20,
30 (random convex teams in mm, hold height 2 x sheet size, one seeded team per N, the
same in both trees); and the time of ``FKSolver.solve_batch`` on 2,000 feasible perturbations of one team at N = 4 and 8
against a loop of the faster peer's calls. The parent reports, per tree, the median over
rounds and the spread (25th-75th percentile over rounds, relative to the median), and the
ratio B / A of the medians.

Usage (trees made with ``git worktree add``; the script never touches a checkout)::

    python bench/bench_fk_revisions.py /tmp/wt_before /tmp/wt_after [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

SIZES = (3, 4, 5, 6, 8, 10, 12, 20, 30)
#: Peers are timed up to this N (above it one VVCM call takes seconds; bench_fk.py has them).
PEER_MAX_N = 12
BATCH_SIZES = (4, 8)
BATCH = 2000
MM = 1000.0
#: CPU seconds of one timed block, and blocks per measurement (``--quick``: 0.1 s, 3; set in
#: the child from the environment variable TAUT_BENCH_QUICK).
BLOCK_S, BLOCKS = (0.1, 3) if os.environ.get("TAUT_BENCH_QUICK") else (0.2, 5)


def _block(fn, arg, calls):
    start = time.process_time()
    for _ in range(calls):
        fn(arg)
    return (time.process_time() - start) / calls


def _per_call(fn, arg):
    """Median CPU seconds per call over ``BLOCKS`` blocks of about ``BLOCK_S`` seconds."""
    for _ in range(3):
        fn(arg)
    calls = max(1, int(BLOCK_S / max(_block(fn, arg, 1), 1e-7)))
    return float(np.median([_block(fn, arg, calls) for _ in range(BLOCKS)]))


def _peers(sheet, hold):
    """``{name: (prepare, call)}`` of the installed peers."""
    out = {}
    try:
        import vvcm_rs
        rs = vvcm_rs.VvcmFk(float(hold), np.asarray(sheet.vertices, np.float32))

        def rs_call(f):
            try:
                return rs.update_stable_solutions(f)
            except vvcm_rs.VvcmError:
                return None
        out["vvcm-rs"] = (lambda f: np.asarray(f, np.float32), rs_call)
    except ImportError:
        pass
    try:
        import VVCM
        cpp = VVCM.VVCM_FK(sheet.n, float(hold), np.asfortranarray(sheet.vertices, np.float32))
        out["VVCM"] = (lambda f: np.asfortranarray(f, np.float32), cpp.update_stable_solutions)
    except ImportError:
        pass
    return out


def child() -> dict:
    """Time the tree on ``PYTHONPATH`` (called in a fresh process)."""
    import taut
    from taut.sheet import FKSolver, Sheet, SheetTeam, random_team
    times: dict[str, float] = {}
    rng = np.random.default_rng(7)
    for n in SIZES:
        sheet, R = random_team(n, rng)
        sheet, R = Sheet(sheet.vertices * MM), R * MM
        hold = 2.0 * sheet.size
        solver = FKSolver(SheetTeam(sheet, hold))
        times[f"solve N={n}"] = _per_call(solver.solve, R)
        times[f"solve+stable N={n}"] = _per_call(lambda f: solver.solve(f).stable, R)
        for name, (prep, call) in (_peers(sheet, hold) if n <= PEER_MAX_N else {}).items():
            times[f"{name} N={n}"] = _per_call(call, prep(R))
    for n in BATCH_SIZES:
        sheet, R = random_team(n, rng)
        sheet, R = Sheet(sheet.vertices * MM), R * MM
        hold = 2.0 * sheet.size
        forms = R[None] + rng.normal(scale=0.002 * sheet.size, size=(BATCH, n, 2))
        d = np.linalg.norm(forms[:, :, None] - forms[:, None], axis=3)
        forms = np.ascontiguousarray(forms[np.all(d <= sheet.side_lengths(), axis=(1, 2))])
        solver = FKSolver(SheetTeam(sheet, hold))
        solver.solve_batch(forms[:2])
        times[f"batch N={n}"] = float(np.median([_block(solver.solve_batch, forms, 1)
                                                 for _ in range(3)])) / len(forms)
        for name, (prep, call) in _peers(sheet, hold).items():
            prepared = [prep(f) for f in forms]
            times[f"{name} loop N={n}"] = float(np.median([
                _block(lambda a: [call(f) for f in a], prepared, 1) for _ in range(3)])) / len(forms)
    return {"file": taut.__file__, "times": times}


def run_tree(tree: str, quick: bool = False) -> dict:
    # TAUT_NUMBA=always: a tree that runs the numpy engine until its kernel cache is warm
    # (docs/compiled_kernels.md) must time the compiled solver here; older trees ignore it.
    env = dict(os.environ, PYTHONPATH=os.path.join(tree, "src"), TAUT_NUMBA="always")
    if quick:
        env["TAUT_BENCH_QUICK"] = "1"
    out = subprocess.run([sys.executable, __file__, "--child"], env=env, check=True,
                         capture_output=True, text=True).stdout
    res = json.loads(out.strip().splitlines()[-1])
    if not os.path.realpath(res["file"]).startswith(os.path.realpath(tree)):
        raise SystemExit(f"the child imported {res['file']}, not the tree {tree}")
    return res["times"]


def _stats(v):
    med = float(np.median(v))
    return med, (float(np.percentile(v, 75)) - float(np.percentile(v, 25))) / med


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2, help="source trees A and B (each with src/taut)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true",
                    help="blocks of 0.1 s, 3 per measurement (a loaded machine)")
    ap.add_argument("--skip-warmup", action="store_true",
                    help="the trees' kernel caches are warm: no untimed first run")
    args = ap.parse_args()
    a, b = args.trees
    for tree in () if args.skip_warmup else (a, b):   # compile the kernels, untimed
        run_tree(tree)
    runs: dict[str, list[dict]] = {a: [], b: []}
    for r in range(args.repeats):
        for tree in ((a, b) if r % 2 == 0 else (b, a)):
            runs[tree].append(run_tree(tree, args.quick))
            print(f"round {r + 1}/{args.repeats}: {tree} done", file=sys.stderr)
    keys = list(runs[a][0])
    print(f"A = {a}, B = {b}; {args.repeats} rounds, medians over rounds (us per "
          f"call / per formation) and spreads (IQR / median)")
    print(f"{'':24s} {'A us':>9s} {'spr':>5s} {'B us':>9s} {'spr':>5s} {'B/A':>6s}")
    med = {}
    for k in keys:
        (ma, sa), (mb, sb) = (_stats([run[k] * 1e6 for run in runs[t]]) for t in (a, b))
        med[k] = (ma, mb)
        print(f"{k:24s} {ma:9.2f} {sa:5.0%} {mb:9.2f} {sb:5.0%} {mb / ma:6.3f}")
    print("ratios peer / taut in the same processes (A -> B):")
    for k in keys:
        if not (k.startswith("solve") or k.startswith("batch")):
            continue
        n = k.split()[-1]
        for peer in ("vvcm-rs", "VVCM"):
            pk = f"{peer} {'loop ' if k.startswith('batch') else ''}{n}"
            if pk in med:
                ra = med[pk][0] / med[k][0]
                rb = med[pk][1] / med[k][1]
                print(f"  {peer:8s} / {k:20s} {ra:8.2f} -> {rb:8.2f}")


if __name__ == "__main__":
    if "--child" in sys.argv:
        print(json.dumps(child()))
    else:
        main()
