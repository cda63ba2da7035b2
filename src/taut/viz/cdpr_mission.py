"""Figures of a warehouse kitting mission (matplotlib): the floor plan with shelves, routes,
deployment sites and boxes; the timeline of phases; each phase's smallest tension and
tipping margins; and an animated GIF of the bases and the platform seen from above.
Only the CLI, examples and users import this module."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation  # noqa: E402

from ..cdpr.mission.mission import PHASE_KINDS, MissionResult  # noqa: E402
from ..cdpr.mission.warehouse import Warehouse, coupled_footprint, to_world_frame  # noqa: E402
from ._save import save_animation, save_figure  # noqa: E402

__all__ = ["plot_mission", "animate_mission", "draw_floor"]

_COLOURS = dict(zip(PHASE_KINDS, ("tab:grey", "tab:purple", "tab:blue", "tab:green",
                                  "tab:orange", "tab:brown")))


def _outline(ax: Any, xy: np.ndarray, **kw: Any) -> Any:
    closed = np.vstack([xy, xy[:1]])
    return ax.plot(closed[:, 0], closed[:, 1], **kw)[0]


def draw_floor(ax: Any, warehouse: Warehouse, result: MissionResult) -> None:
    """Floor, shelves, routes, sites (deployed footprints) and boxes on ``ax`` (m)."""
    floor = np.asarray(warehouse.floor.exterior.coords)
    ax.plot(floor[:, 0], floor[:, 1], color="black", lw=1.5)
    for sh in warehouse.shelves:
        xy = np.asarray(sh.footprint.exterior.coords)
        ax.fill(xy[:, 0], xy[:, 1], color="0.75", zorder=1)
        ax.text(*xy[:-1].mean(axis=0), sh.name, ha="center", va="center", fontsize=8)
    for nav in result.routes:
        if nav.success and len(nav.poses):
            ax.plot(nav.poses[:, 0], nav.poses[:, 1], color="tab:grey", lw=1, ls="--")
    for k, site in enumerate(result.sites):
        body = to_world_frame(site.pose, coupled_footprint(site.robot, deployed=True))
        _outline(ax, body, color="tab:blue", lw=1)
        ax.text(site.pose[0], site.pose[1], f"site {k + 1}", fontsize=7, color="tab:blue",
                ha="center")
    unserved = {u.name for u in result.unserved}
    for t in warehouse.tasks:
        c = "tab:red" if t.name in unserved else "tab:green"
        ax.plot(*t.pick[:2], marker="s", color=c, ms=4)
        ax.plot(*t.place[:2], marker="o", color=c, ms=4, mfc="none")
        ax.annotate(t.name, t.pick[:2], fontsize=6, color=c, xytext=(2, 2),
                    textcoords="offset points")
    ax.plot(*warehouse.start[:2], marker="*", color="black", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def plot_mission(warehouse: Warehouse, result: MissionResult, path: str | Path, *,
                 dpi: int = 120) -> None:
    """Floor plan (squares: picks, circles: places, red: unserved), the phase timeline and
    each phase's smallest tension (N) and tipping (N m) margins, saved to ``path``."""
    fig = plt.figure(figsize=(11, 8))
    grid = fig.add_gridspec(3, 1, height_ratios=[3, 0.8, 1.6])
    ax = fig.add_subplot(grid[0])
    draw_floor(ax, warehouse, result)
    ax.set_title(f"{warehouse.name}: {len(result.served)} boxes moved in "
                 f"{result.total_time:.1f} s (1 m/s baseline {result.baseline_total_time:.1f} s)")
    tl = fig.add_subplot(grid[1])
    for p in result.phases:
        tl.barh(0, p.end - p.start, left=p.start, color=_COLOURS[p.kind],
                edgecolor="white" if p.success else "red", lw=0.5)
    tl.set_yticks([])
    tl.set_xlabel("time [s]")
    tl.legend(handles=[plt.Rectangle((0, 0), 1, 1, color=c) for c in _COLOURS.values()],
              labels=list(_COLOURS), ncol=6, fontsize=7, loc="upper center",
              bbox_to_anchor=(0.5, 1.6), frameon=False)
    mg = fig.add_subplot(grid[2])
    x = np.arange(len(result.phases))
    ten = [p.min_tension_margin for p in result.phases]
    tip = [p.min_tipping_margin for p in result.phases]
    mg.bar(x - 0.2, ten, 0.4, label="tension margin [N]", color="tab:blue")
    mg.bar(x + 0.2, np.minimum(tip, 1e3), 0.4, label="tipping margin [N m]",
           color="tab:orange")
    mg.axhline(0, color="black", lw=0.8)
    mg.set_xticks(x, [f"{p.kind} {p.task}".strip() for p in result.phases], rotation=90,
                  fontsize=6)
    mg.set_ylabel("smallest margin")
    mg.set_yscale("symlog", linthresh=10)
    mg.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=dpi)
    plt.close(fig)


def animate_mission(warehouse: Warehouse, result: MissionResult, path: str | Path, *,
                    frames: int = 120, fps: int = 12) -> None:
    """Animated GIF of the mission seen from above: the coupled bases' footprint and the
    platform (red while carrying a box), with the current phase in the title."""
    fig, ax = plt.subplots(figsize=(8, 5))
    draw_floor(ax, warehouse, result)
    t = result.track_times
    idx = np.unique(np.linspace(0, max(len(t) - 1, 0), frames).round().astype(int)) \
        if len(t) else np.zeros(0, dtype=int)
    body = coupled_footprint(warehouse.robot)
    (foot,) = ax.plot([], [], color="tab:purple", lw=1.5)
    (dot,) = ax.plot([], [], "o", color="tab:red", ms=5)
    starts = np.array([p.start for p in result.phases])

    def update(j: int) -> Any:
        i = idx[j]
        xy = to_world_frame(result.track_bases[i], body)
        foot.set_data(*np.vstack([xy, xy[:1]]).T)
        dot.set_data([result.track_platform[i, 0]], [result.track_platform[i, 1]])
        k = max(int(np.searchsorted(starts, t[i], side="right")) - 1, 0)
        p = result.phases[k] if result.phases else None
        ax.set_title(f"t = {t[i]:.1f} s" + (f"  {p.kind} {p.task}" if p else ""))
        return foot, dot

    anim = FuncAnimation(fig, update, frames=len(idx), blit=False)
    save_animation(anim, path, fps=fps)
    plt.close(fig)
