"""Figures of MuJoCo cross-checks (matplotlib only: no OpenGL context needed): the settled
sheet of every checked state beside taut's prediction, and an animation of a drop."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..physics.sheet import EquilibriaCheck, SettleResult  # noqa: E402
from .sheet import KIND_COLOURS, sheet_unit  # noqa: E402
from ._save import save_figure, save_animation  # noqa: E402

__all__ = ["plot_equilibria_check", "animate_settle"]


def _draw_sheet(ax: Any, nodes: np.ndarray, triangles: np.ndarray, formation: np.ndarray,
                hold_height: float, units: str | None = None) -> None:
    ax.plot_trisurf(nodes[:, 0], nodes[:, 1], nodes[:, 2], triangles=triangles,
                    color="tab:blue", alpha=0.35, edgecolor="0.3", linewidth=0.3)
    for i, (x, y) in enumerate(formation):
        ax.plot([x, x], [y, y], [0, hold_height], color="0.35", lw=1.2)
        ax.text(x, y, hold_height * 1.05, str(i + 1), fontsize=8, ha="center")
    ax.set_zlim(0, hold_height * 1.1)
    for axis in "xyz":           # sheets use any consistent length unit (examples: mm)
        getattr(ax, f"set_{axis}label")(f"{axis} [{sheet_unit(units)}]", fontsize=7)
    span = np.ptp(np.vstack([nodes[:, :2], formation]), axis=0)
    ax.set_box_aspect((max(span[0], 1e-9), max(span[1], 1e-9), hold_height * 1.1))


def plot_equilibria_check(check: EquilibriaCheck, formation: np.ndarray, hold_height: float,
                          path: str | Path | None = None, *, units: str | None = None,
                          title: str | None = None) -> Any:
    """One 3D panel per state: the simulated sheet settled with the object tied at taut's
    contact point, taut's object position (coloured by taut's verdict) and the released
    ball's rest position (black cross; a failed release is named in red in the panel's
    title instead, and a marginal state, left by the released ball, is titled in red).
    Returns the figure; saves it when ``path``."""
    n = max(len(check.states), 1)
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig = plt.figure(figsize=(4.2 * cols, 4.0 * rows))
    u = f" {sheet_unit(units)}"
    for k, s in enumerate(check.states):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        _draw_sheet(ax, s.nodes, s.triangles, np.asarray(formation), hold_height, units)
        ax.scatter(*s.predicted, s=60, color=KIND_COLOURS.get(s.kind, "k"),
                   edgecolor="k", depthshade=False, label="taut")
        if s.success or s.status == "not_strict":
            ax.scatter(*s.settled, s=50, marker="x", color="k", depthshade=False,
                       label="physics, released")
            released = f"released dz = {s.difference[2]:+.1f}{u}"
            if s.status == "not_strict":
                released += f" MARGINAL (basin <= {s.basin:.2g}{u})"
        else:
            released = f"run FAILED ({s.status.replace('_', ' ')}): see the message"
        label = "{" + ",".join(str(i + 1) for i in s.taut) + "}"
        verdict = ("held" if s.held else "not held") + ("" if s.resolved else " (unresolved)")
        ax.set_title(f"{label} taut: {s.kind.replace('_', ' ')}; physics: {verdict}\n"
                     f"tied dz = {s.tied_difference[2]:+.1f}{u}, pull {s.sliding:.2g} mg\n"
                     f"{released}", fontsize=8, color="k" if s.success else "tab:red")
        ax.tick_params(labelsize=6)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=130)
    return fig


def animate_settle(result: SettleResult, formation: np.ndarray, hold_height: float,
                   path: str | Path, *, fps: int = 10, units: str | None = None) -> None:
    """Write a GIF of a drop (:func:`taut.physics.settle` with ``trace=True``); axes in
    ``units`` (the scenario's, default "sheet units")."""
    from matplotlib.animation import FuncAnimation

    if result.frames is None or result.trace is None:
        raise ValueError("settle(..., trace=True) records the frames an animation needs")
    frames, trace = result.frames, result.trace
    fig = plt.figure(figsize=(5, 4.5))
    ax = fig.add_subplot(projection="3d")

    def draw(k: int) -> None:
        ax.clear()
        _draw_sheet(ax, frames[k], result.triangles, np.asarray(formation), hold_height,
                    units)
        ax.scatter(*trace[k, 1:], s=40, color="tab:red", depthshade=False)
        ax.set_title(f"t = {trace[k, 0]:.1f} s", fontsize=9)

    anim = FuncAnimation(fig, draw, frames=len(frames), interval=1000 / fps)
    save_animation(anim, path, fps=fps)
    plt.close(fig)
