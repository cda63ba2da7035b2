"""Figures of cable-driven parallel robots (matplotlib): wrench-feasible workspace slices and
3D views with and without tipping, and axis-capacity bar charts in the style of FASTKIT's
Fig. 14. Only the CLI and users import this module; solvers never do."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cdpr.model.robot import CableRobot  # noqa: E402
from ..cdpr.workspace.wrench_feasible import WorkspaceResult  # noqa: E402
from ..cdpr.sets.wrench import AxisCapacities  # noqa: E402
from ._save import save_figure  # noqa: E402

__all__ = ["draw_robot_outline", "plot_workspace", "plot_axis_capacities"]


def draw_robot_outline(ax, robot: CableRobot, axes: tuple[int, int] = (0, 2)) -> None:
    """Project exit points, structures and mobile-base footprints onto a plane of a 2D axis
    (``axes`` picks the world coordinates, default x-z)."""
    i, j = axes
    ex = robot.exits_world
    ax.scatter(ex[:, i], ex[:, j], marker="v", color="0.2", s=22, zorder=3, label="exit points")
    for k, base in enumerate(robot.bases):
        sel = robot.cable_base == k
        if base.mobile:
            c = base.support_world()
            if j == 2:
                lo, hi = c[:, i].min(), c[:, i].max()
                ax.plot([lo, hi], [0, 0], color="0.3", lw=5, solid_capstyle="butt")
            for e in ex[sel]:
                ax.plot([e[i], e[i]], [0 if j == 2 else e[j], e[j]], color="0.6", lw=1)


def plot_workspace(result: WorkspaceResult, robot: CableRobot,
                   path: str | Path | None = None, *, title: str | None = None):
    """Draw a wrench-feasible workspace with and without tipping.

    A grid with one flat axis is drawn as a 2D slice (feasible with tipping: filled,
    feasible only without tipping: hollow, infeasible: small grey dots) next to the frame
    and bases; otherwise as a 3D scatter of the two workspaces. Returns the figure and
    saves it when ``path`` is given.
    """
    pts = result.points
    flat = [k for k in range(3) if np.ptp(pts[:, k]) == 0.0]
    f = result.feasible
    ft = result.feasible_tipping if result.feasible_tipping is not None else f
    label = title or f"{robot.name}: wrench-feasible workspace"
    if flat:
        i, j = [k for k in range(3) if k != flat[0]][:2]
        fig, ax = plt.subplots(figsize=(9, 4.8))
        draw_robot_outline(ax, robot, (i, j))
        ax.scatter(pts[~f, i], pts[~f, j], s=3, color="0.8", label="infeasible")
        if result.feasible_tipping is not None:
            only = f & ~ft
            ax.scatter(pts[only, i], pts[only, j], s=22, facecolors="none",
                       edgecolors="tab:orange", label="feasible, but a base tips")
            ax.scatter(pts[ft, i], pts[ft, j], s=22, color="tab:blue",
                       label="feasible with tipping constraints")
        else:
            ax.scatter(pts[f, i], pts[f, j], s=22, color="tab:blue", label="feasible")
        if robot.desired_workspace is not None:
            lo, hi = robot.desired_workspace
            ax.add_patch(plt.Rectangle((lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j],
                                       fill=False, ls="--", color="tab:green",
                                       label="desired workspace"))
        names = "xyz"
        ax.set_xlabel(f"{names[i]} [m]")
        ax.set_ylabel(f"{names[j]} [m]")
        ax.set_aspect("equal")
        cov = f"coverage {100 * result.coverage:.0f} %"
        if result.coverage_tipping is not None:
            cov += f" without tipping, {100 * result.coverage_tipping:.0f} % with tipping"
        ax.set_title(f"{label}\n{cov} (slice {names[flat[0]]} = {pts[0, flat[0]]:g} m)",
                     fontsize=10)
        ax.legend(fontsize=7, loc="upper center", ncol=3, bbox_to_anchor=(0.5, -0.14))
    else:
        fig = plt.figure(figsize=(11, 5))
        panels = [("tension limits only", f)]
        if result.feasible_tipping is not None:
            panels.append(("tension and tipping limits", ft))
        for k, (name, mask) in enumerate(panels):
            ax = fig.add_subplot(1, len(panels), k + 1, projection="3d")
            ex = robot.exits_world
            ax.scatter(ex[:, 0], ex[:, 1], ex[:, 2], marker="v", color="0.2", s=20)
            ax.scatter(pts[mask, 0], pts[mask, 1], pts[mask, 2], s=4, color="tab:blue",
                       alpha=0.5)
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_zlabel("z [m]")
            ax.set_title(f"{name}: {int(mask.sum())}/{len(mask)} points", fontsize=9)
        fig.suptitle(label, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=150)
    return fig


def _pose_row(cap: AxisCapacities, pose_index: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(positive, negative, feasible)`` of one pose (row ``pose_index`` of a batch)."""
    if cap.positive.ndim == 1:
        return cap.positive, cap.negative, cap.feasible
    return cap.positive[pose_index], cap.negative[pose_index], cap.feasible[pose_index]


def plot_axis_capacities(without: AxisCapacities, with_tipping: AxisCapacities | None = None,
                         path: str | Path | None = None, *, title: str | None = None,
                         pose_index: int = 0):
    """Bar chart of the largest force (N) and moment (N m) the platform can resist along
    and about each axis (the smaller of the + and - directions, as in FASTKIT Fig. 14),
    tension limits only vs. with tipping, for capacities of one pose (or pose
    ``pose_index`` of a batch). Returns the figure; saves it when ``path``."""
    sets = [("tension limits", without)]
    if with_tipping is not None:
        sets.append(("with tipping", with_tipping))
    n = len(without.labels)
    groups = [("forces [N]", range(min(3, n)))] + ([("moments [N m]", range(3, 6))]
                                                   if n == 6 else [])
    fig, axes = plt.subplots(1, len(groups), figsize=(4.5 * len(groups), 3.6), squeeze=False)
    width = 0.8 / len(sets)
    infeasible = []
    for ax, (gname, ks) in zip(axes[0], groups):
        kl = list(ks)
        x = np.arange(len(kl))
        for s, (sname, cap) in enumerate(sets):
            pos, neg, ok = _pose_row(cap, pose_index)
            at = x + (s - (len(sets) - 1) / 2) * width
            bars = ax.bar(at, np.minimum(pos, neg)[kl], width, label=sname)
            if not ok.all():                # the weight alone is not held at this pose
                infeasible.append(sname)
            for xb, k in zip(at, kl):
                if not ok[k].all():
                    ax.text(xb, 0.0, " 0: infeasible", rotation=90, ha="center",
                            va="bottom", fontsize=7, color=bars.patches[0].get_facecolor())
        ax.set_xticks(x, [without.labels[k] for k in kl])
        ax.set_ylabel(gname)
        ax.legend(fontsize=7)
    head = title or "wrench capability (min of + and - directions)"
    for sname in dict.fromkeys(infeasible):
        head += f"\n{sname}: infeasible at this pose (the weight alone is not held)"
    fig.suptitle(head, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=150)
    return fig
