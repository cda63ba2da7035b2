"""Benchmark of the CDPR control simulation (taut.cdpr.simulate / monte_carlo) on FASTKIT.

Measures, in one run on this machine (interleaved repeats, median and min-max spread):
  * simulated seconds per wall second (and per process CPU second, the figure a loaded
    shared machine distorts least) at a 1 kHz control rate for the velocity and torque
    controllers, numba backend (the compiled loop) and numpy backend (the reference loop), for
    the whole call (set-up: reference tensions, context, initial equilibrium) and the loop,
    with the default encoder sensing (pose by cable forward kinematics every step) and, on
    the numba backend, with the ideal pose (the ratio is the cost of the estimator);
  * a batched Monte Carlo over 100 seeded 5 mm exit-error plants (one compiled loop over all
    plants) against 100 single runs extrapolated from 10, and its statistics.
Run: ``python bench/bench_cdpr_control.py [--repeats 3] [--runs 100]`` (numba, a dependency of taut).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from taut.cdpr import (ModelErrors, Sensing, TorqueController, VelocityController,
                       monte_carlo, pick_and_place, simulate, with_stabilisers)
from taut.cdpr.control.simulate import _loop_numba, _prepare
from taut.io.cdpr_model import load_cdpr_model

WAYPOINTS = [[-1.5, 0.0, 0.6], [-1.5, 0.0, 1.1], [1.5, 0.0, 1.1], [1.5, 0.0, 0.6]]


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def cpu_timed(fn):
    """Wall and process CPU seconds of one call (on a shared machine the CPU time is the
    load-robust figure: what the run costs when it has a core to itself)."""
    w0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w0, time.process_time() - c0


def fmt(xs):
    return f"{statistics.median(xs):7.1f}x  [{min(xs):.1f} .. {max(xs):.1f}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--runs", type=int, default=100)
    args = ap.parse_args()
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    ref = pick_and_place(robot, WAYPOINTS, speed=1.0, dwell=0.5)
    sim_s = ref.duration + 1.0                                 # + 1 s settling pre-roll
    errs = ModelErrors(exit_offset=0.005, seed=0)
    ctls = {"velocity": VelocityController(), "torque": TorqueController()}
    for c in ctls.values():                                    # compile / warm up
        simulate(robot, ref, c, model_errors=errs, backend="numba", duration=0.2)
    setup_t, loop_t = [], {name: [] for name in ctls}
    rates: dict[tuple[str, str], list[float]] = {}
    for _ in range(args.repeats):                              # interleaved
        for name, c in ctls.items():
            dt_s, setup = timed(lambda: _prepare(robot, ref, c, errs, None, 1000.0, None, None,
                                                 1, None, 1.0))
            setup_t.append(dt_s)
            loop_t[name].append(timed(lambda: _loop_numba(setup, c, 1, 1))[0])
            for eng in ("numba", "numpy"):
                dt, cpu = cpu_timed(lambda: simulate(robot, ref, c, model_errors=errs,
                                                     backend=eng))
                rates.setdefault((name, eng + " encoders"), []).append(sim_s / dt)
                rates.setdefault((name, eng + " encoders CPU"), []).append(sim_s / cpu)
            dt, cpu = cpu_timed(lambda: simulate(robot, ref, c, model_errors=errs,
                                                 backend="numba",
                                                 sensing=Sensing(ideal_pose=True)))
            rates.setdefault((name, "numba ideal pose"), []).append(sim_s / dt)
            rates.setdefault((name, "numba ideal pose CPU"), []).append(sim_s / cpu)
    print(f"FASTKIT pick-and-place, {ref.duration:.2f} s + 1 s pre-roll = {sim_s:.2f} s "
          "simulated at 1 kHz (median of", args.repeats, "interleaved runs)")
    print(f"  set-up of one run (reference tensions, context, equilibrium): "
          f"{1e3 * statistics.median(setup_t):.0f} ms [{1e3 * min(setup_t):.0f} .. "
          f"{1e3 * max(setup_t):.0f}]")
    print("  real-time factor, whole call (simulated s per wall s; 'CPU': per process CPU s):")
    for (name, eng), xs in rates.items():
        print(f"    {name:8s} {eng:21s} {fmt(xs)}")
    for name in ctls:
        print(f"    {name:8s} numba loop only {fmt([sim_s / x for x in loop_t[name]])}")
    # Monte Carlo
    seeds = [ModelErrors(exit_offset=0.005, seed=s) for s in range(args.runs)]
    for name, c in ctls.items():
        dt_mc, mc = timed(lambda: monte_carlo(robot, ref, c, seeds, backend="numba"))
        dt_one = statistics.median(timed(lambda: simulate(robot, ref, c, model_errors=s,
                                                          backend="numba"))[0]
                                   for s in seeds[:10])
        print(f"  Monte Carlo {name}: {args.runs} plants batched in {dt_mc:.2f} s "
              f"({args.runs * sim_s / dt_mc:.0f} simulated s per wall s) vs "
              f"{args.runs} single runs ~{args.runs * dt_one:.1f} s (from 10)")
        print(f"    ok {int(mc.success.sum())}/{args.runs}; slack time median "
              f"{np.median(mc.slack_time):.3f} s (max {mc.slack_time.max():.3f}); worst "
              f"over-tension median {np.median(np.maximum(mc.worst_over_tension, 0)):.2f} N "
              f"(max {mc.worst_over_tension.max():.2f}); tension range "
              f"{mc.min_tension.min():.2f} .. {mc.max_tension.max():.2f} N; max tracking "
              f"error median {1e3 * np.median(mc.max_tracking_error):.2f} mm (max "
              f"{1e3 * mc.max_tracking_error.max():.2f}); min tipping margin "
              f"{mc.min_tipping_margin.min():.1f} N m")
    print("machine: shared with other jobs (load average at start shown by `uptime`); "
          "numbers are indicative")


if __name__ == "__main__":
    main()
