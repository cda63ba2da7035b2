"""Compile every numba kernel into the on-disk cache, then write the warm stamp.

Run as ``python -m taut._warmup`` with ``TAUT_NUMBA=always`` (``taut compile``, the
Makefile's install step, and :func:`taut._jit.warm_in_background` do): it runs the
library's own entry points on small inputs of every kind a user's call passes to the
kernels (the same array types, so the same compiled specialisations), so that a later
process finds them all cached (docs/compiled_kernels.md).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from . import _jit

__all__ = ["warm", "bytecode"]

#: The planning paper's corridor (examples/plan/paper_corridor.yaml): a plan that runs
#: the lattice search, the clearance proofs and formation changes.
CORRIDOR = {
    "units": "m",
    "free_space": [[0, -1], [6, -1], [6, 1], [0, 1]],
    "obstacles": [{"id": "1", "center": [2.0, 0.0], "radius": 0.10, "height": 0.10},
                  {"id": "2", "center": [4.0, 0.0], "radius": 0.15, "height": 0.20}],
    "start": [0.8, 0.0], "goal": [5.2, 0.0],
    "team": {"regular": {"n": 3, "circumradius": 0.5773502691896258}, "hold_height": 0.5,
             "robot_radius": 0.15, "height_safety": 0.05, "lateral_safety": 0.05,
             "speed": 0.1, "rotation_speed": 0.3, "mass": 0.17},
}


def _sheet_kernels() -> None:
    """FK (every method the kernels take, hull path above ``COMPILED_MAX_N``, one and
    many formations), simulation and IK."""
    from .sheet import (COMPILED_MAX_N, FKSolver, Sheet, SheetTeam, forward_kinematics,
                        forward_kinematics_batch, inverse_kinematics, simulate)

    rng = np.random.default_rng(0)
    for n in (3, 4, 5, 8, COMPILED_MAX_N + 1):
        team = SheetTeam(Sheet.regular(n, 1.0), hold_height=1.0, mass=1.0)
        formation = 0.8 * team.sheet.vertices + 0.01 * rng.standard_normal((n, 2))
        for method in ("fast", "subsets"):
            forward_kinematics(team, formation, method=method)
        shifts = 0.01 * rng.standard_normal((4, 1, 2))
        forward_kinematics_batch(team, formation + shifts)
        FKSolver(team).solve_batch(formation + shifts)
    team = SheetTeam(Sheet.regular(4, 1.0), hold_height=1.0, mass=1.0)
    ik = inverse_kinematics(team, object_position=(0.0, 0.0, 0.4))
    if ik.formation is not None:
        path = ik.formation + np.linspace(0.0, 0.2, 5)[:, None, None] * [1.0, 0.0]
        simulate(team, path)


def _plan_kernels() -> None:
    from .io.plan_scenario import plan_scenario_from_mapping
    from .plan import plan

    plan(plan_scenario_from_mapping(CORRIDOR))


def _cdpr_kernels() -> None:
    from .cdpr import (ComputedTorqueController, TorqueController, VelocityController,
                       pick_and_place, simulate)
    from .cdpr import with_stabilisers
    from .io.cdpr_model import load_cdpr_model

    robot = with_stabilisers(load_cdpr_model("fastkit"))
    ref = pick_and_place(robot, [[-0.2, 0.0, 1.0], [0.2, 0.0, 1.0]], dwell=0.05)
    # the compiled loop (velocity, torque) and the compiled plant under a Python controller
    for controller in (VelocityController(), TorqueController(), ComputedTorqueController()):
        simulate(robot, ref, controller, backend="numba")


def bytecode(package: str = os.path.dirname(os.path.abspath(__file__))) -> bool:
    """Byte-compile every module of ``package`` (default: taut's own folder) into its
    ``__pycache__``, as pip does when it installs a wheel; returns whether every file was
    written. A source or editable install has no bytecode until a command imports a
    module, so the first ``taut fk`` after ``taut compile`` paid for compiling its modules
    (0.40 s against 0.26 s warm, 1.5x, bench/bench_startup.py, 2026-12-05). A read-only
    install is left as it is (nothing printed)."""
    import compileall

    return bool(compileall.compile_dir(package, quiet=2, workers=1))


def warm() -> float:
    """Compile (or load) every kernel and the package's bytecode, write the stamp;
    returns the seconds it took."""
    if not _jit.HAVE_NUMBA:
        raise RuntimeError(f"taut._warmup needs TAUT_NUMBA=always and numba: "
                           f"{_jit.not_compiled_reason()}")
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        _sheet_kernels()
        _plan_kernels()
        _cdpr_kernels()
    bytecode()
    seconds = time.perf_counter() - t0
    stamp = _jit.stamp_path()
    os.makedirs(os.path.dirname(stamp), exist_ok=True)
    partial = f"{stamp}.{os.getpid()}.tmp"
    with open(partial, "w") as f:
        f.write(f"taut kernels compiled in {seconds:.1f} s\n")
    os.replace(partial, stamp)
    return seconds


def main(argv: list[str]) -> int:
    """``python -m taut._warmup [--background]``; in the background at the lowest
    priority, silent; the lock removed when done."""
    background = "--background" in argv
    if background and hasattr(os, "nice"):
        os.nice(19)
    try:
        seconds = warm()
    finally:
        try:
            os.remove(_jit.stamp_path() + ".lock")
        except OSError:
            pass
    if not background:
        print(f"taut: compiled kernels ready in {seconds:.1f} s ({_jit.stamp_path()})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
