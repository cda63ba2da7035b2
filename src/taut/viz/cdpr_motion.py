"""Figures of mobile-CDPR motion analyses (matplotlib): twist-capacity bar charts in the
style of FASTKIT's Fig. 13 (and wrench capacities, Fig. 14) with bases moving vs fixed, and a
top view of a deployment. Only the CLI and users import this module; solvers never do."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cdpr.deployment.deploy import DeploymentResult  # noqa: E402
from ._save import save_figure  # noqa: E402

__all__ = ["plot_capacity_bars", "plot_deployment"]


def plot_capacity_bars(series: dict[str, np.ndarray], labels: Sequence[str],
                       units: Sequence[str], title: str, path: str | Path | None = None):
    """Grouped bars of axis capacities (one group per axis, one bar per series, e.g.
    ``{"bases moving": ..., "bases fixed": ...}``), split into two panels by unit (linear
    m/s | angular rad/s, or forces N | moments N m). Returns the figure."""
    groups = sorted(set(units), key=list(units).index)
    fig, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 3.4), squeeze=False)
    w = 0.8 / max(len(series), 1)
    for ax, unit in zip(axes[0], groups):
        idx = [k for k, u in enumerate(units) if u == unit]
        x = np.arange(len(idx))
        for s, (name, vals) in enumerate(series.items()):
            v = np.asarray(vals, dtype=float)[idx]
            bars = ax.bar(x + (s - (len(series) - 1) / 2) * w, v, w, label=name)
            ax.bar_label(bars, fmt="%.2f", fontsize=7)
        ax.set_xticks(x, [labels[k] for k in idx])
        ax.set_ylabel(unit)
        ax.grid(axis="y", alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=130)
        plt.close(fig)
    return fig


def plot_deployment(result: DeploymentResult, path: str | Path | None = None,
                    title: str | None = None):
    """Top view (x-y) of a deployment: base footprints and frames, exit points, the
    workspace box and its verification points (green feasible, red not). Returns the
    figure."""
    robot = result.robot
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    box = result.workspace
    ax.add_patch(plt.Rectangle((float(box[0, 0]), float(box[0, 1])),
                               *(box[1, :2] - box[0, :2]), fill=False, lw=1.5,
                               ec="tab:blue", label="workspace"))
    ok = result.point_feasible
    ax.scatter(result.points[ok, 0], result.points[ok, 1], s=6, c="tab:green",
               label="feasible (tipping)")
    if np.any(~ok):
        ax.scatter(result.points[~ok, 0], result.points[~ok, 1], s=8, c="tab:red",
                   label="infeasible")
    for base in robot.bases:
        if base.mobile:
            c = base.support_world()
            ax.fill(c[:, 0], c[:, 1], alpha=0.25, color="0.4")
            x, y, th = base.pose
            ax.annotate("", xy=(x + 0.4 * np.cos(th), y + 0.4 * np.sin(th)), xytext=(x, y),
                        arrowprops=dict(arrowstyle="->"))
            # below the footprint (not a fixed offset, which overlapped large footprints)
            ax.text(x, float(c[:, 1].min()) - 0.08,
                    f"{base.name}\nx {x:.2f} m, y {y:.2f} m, {np.degrees(th):.1f}°",
                    ha="center", va="top", fontsize=7)
    ex = robot.exits_world
    ax.scatter(ex[:, 0], ex[:, 1], marker="v", c="k", s=14, label="exit points")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.margins(0.08, 0.25)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=4,
              frameon=False)
    ax.set_title(title or (f"deployment, top view: worst wrench margin {result.margin:.3g} "
                           "N (N m for moments)"
                           + ("" if result.success else " (not feasible)")), fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=130)
        plt.close(fig)
    return fig
