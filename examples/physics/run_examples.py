"""Regenerate the tables and figures of examples/physics/README.md.

Usage::

    python examples/physics/run_examples.py

Needs the physics extra (``pip install 'taut[physics]'``). Prints Markdown tables (taut
vs MuJoCo on the FK paper's Examples 1 and 2, FASTKIT tipping at a few poses) and writes
``example1_settled.png`` and ``example2_settled.png`` next to this file.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from taut.cdpr import distribute_tensions
from taut.io import load_sheet_scenario
from taut.io.cdpr_model import load_cdpr_model
from taut.physics import replay_equilibria, replay_tipping
from taut.viz.physics import plot_equilibria_check

HERE = Path(__file__).resolve().parent
SHEET = HERE.parent / "sheet"


def sheet_table(name: str, path: Path, figure: str) -> None:
    sc = load_sheet_scenario(path)
    r = replay_equilibria(sc.team, sc.formation)
    print(f"\n### {name}\n\n{r.message} (mesh {r.mesh}, ball radius {r.ball:.1f} mm)\n")
    print("| taut set | taut: z_o [mm] | taut says | physics | pull / mg | taut's pull / mg "
          "| tied dx, dy, dz [mm] | released dx, dy, dz [mm] | s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in r.states:
        label = "{" + ",".join(str(i + 1) for i in s.taut) + "}"
        fmt = lambda d: ", ".join(f"{v:+.1f}" for v in d)  # noqa: E731
        released = fmt(s.difference) if s.success else f"FAILED: {s.message}"
        held = ("held" if s.held else "not held") + ("" if s.resolved else " (unresolved)")
        print(f"| {label} | {s.predicted[2]:.1f} | {s.kind.replace('_', ' ')} | "
              f"{held} | {s.sliding:.3f} | {s.predicted_sliding:.3f} | "
              f"{fmt(s.tied_difference)} | {released} | {s.time:.1f} |")
    fig = plot_equilibria_check(r, sc.formation, sc.team.hold_height, HERE / figure, units="mm",
                                title=name)
    plt.close(fig)


def tipping_table() -> None:
    robot = load_cdpr_model("fastkit")
    print("\n### FASTKIT tipping (lp_min_sum tensions, tipping constraints not imposed)\n")
    print("| pose x, z [m] | taut margin [N m] | taut | physics (active, passive) "
          "| tilt [deg] | slip [mm] |")
    print("|---|---|---|---|---|---|")
    for x, z in ((-2.0, 0.2), (2.0, 0.2), (1.5, 1.0), (-1.0, 1.4), (0.0, 1.4)):
        pose = [x, 0.0, z, 0.0, 0.0, 0.0]
        t = distribute_tensions(robot, pose, "lp_min_sum", tipping=False).tensions
        c = replay_tipping(robot, pose, t)
        print(f"| {x:+.1f}, {z:.1f} | {c.margin:+.1f} | "
              f"{'stays' if c.taut_stays else 'tips'} | {', '.join(c.verdicts)} | "
              f"{', '.join(f'{v:.1f}' for v in c.tilt)} | "
              f"{', '.join(f'{1000 * v:.1f}' for v in c.slip)} |")


if __name__ == "__main__":
    from taut.cli._progress import working  # progress on stderr past 2 s
    with working("physics examples"):
        np.set_printoptions(precision=2)
        sheet_table("FK paper Example 1 (4 robots)", SHEET / "example1.yaml",
                    "example1_settled.png")
        sheet_table("FK paper Example 2 (8 robots, r2 and r4 at +-353 mm)",
                    SHEET / "example2_r2_r4_353mm.yaml", "example2_settled.png")
        tipping_table()
