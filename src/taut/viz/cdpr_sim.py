"""Figures of CDPR control simulations (matplotlib): tracking error, cable tensions with their
limits shaded, tipping margins, motor torques, comparisons of controllers, and a 3D animation
of platform, cables and bases. Only the CLI, examples and users import this module."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Mapping

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation  # noqa: E402

from ..cdpr.kinematics._bases import moved_exits  # noqa: E402
from ..cdpr.kinematics.cables import rotation_matrices  # noqa: E402
from ..cdpr.model.robot import CableRobot  # noqa: E402
from ..cdpr.control.simulate import ControlResult  # noqa: E402
from ._save import save_figure, save_animation  # noqa: E402

__all__ = ["plot_control", "plot_comparison", "animate_control"]


def _tension_panel(ax, r: ControlResult, title: str = "") -> None:
    lo, hi = float(r.t_min.min()), float(r.t_max.max())
    top = max(hi * 1.15, float(r.tensions.max()) * 1.05)
    ax.axhspan(0.0, lo, color="tab:red", alpha=0.12, lw=0, label="outside [t_min, t_max]")
    ax.axhspan(hi, top, color="tab:red", alpha=0.12, lw=0)
    for j, name in enumerate(r.cable_names):
        ax.plot(r.times, r.tensions[:, j], lw=0.8, label=name)
    ax.set_ylim(0.0, top)
    ax.set_ylabel("tension (N)")
    ax.set_title(title or "cable tensions", fontsize=9)


def plot_control(r: ControlResult, path: str | Path | None = None, title: str | None = None):
    """Four panels against time: tracking error (mm), tensions with the limits shaded,
    tipping margins (N m, > 0 stable), motor torques (N m) with the saturation limit.
    Returns the figure (written to ``path`` when given)."""
    fig, ax = plt.subplots(4, 1, figsize=(9, 9.5), sharex=True)
    ax[0].plot(r.times, 1e3 * r.tracking_error, c="k", lw=1)
    ax[0].set_ylabel("tracking error (mm)")
    _tension_panel(ax[1], r)
    ax[1].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    if r.tipping_margin.shape[1]:
        for j, name in enumerate(r.edge_names):
            ax[2].plot(r.times, r.tipping_margin[:, j], lw=0.8, label=name)
        ax[2].axhline(0.0, c="tab:red", lw=1, label="tips below 0")
        ax[2].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                     borderaxespad=0.0)
    ax[2].set_ylabel("tipping margin (N m)")
    ax[2].set_title("tipping margin of each support edge" if r.tipping_margin.shape[1]
                    else "tipping margin (no mobile base)", fontsize=9)
    for j, name in enumerate(r.cable_names):
        ax[3].plot(r.times, r.motor_torques[:, j], lw=0.8, label=name)
    lim = float(np.abs(r.motor_torques).max())
    ax[3].set_ylabel("motor torque (N m)")
    ax[3].set_xlabel("time (s)")
    ax[3].set_title("motor torques", fontsize=9)
    ax[3].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax[0].set_title("tracking error of the platform position", fontsize=9)
    for a in ax:
        a.grid(alpha=0.3)
    ax[3].set_ylim(-1.1 * max(lim, 1e-6), 1.1 * max(lim, 1e-6))
    head = title or f"{r.controller.get('name', '')} control: {r.message}"
    fig.suptitle(textwrap.fill(head, 110), fontsize=9)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=130)
        plt.close(fig)
    return fig


def plot_comparison(results: Mapping[str, ControlResult], path: str | Path | None = None,
                    title: str = ""):
    """Tensions (limits shaded) and tracking error of several runs side by side (the
    paper's velocity vs torque control comparison). Returns the figure."""
    n = len(results)
    fig, ax = plt.subplots(2, n, figsize=(5.2 * n, 6), sharex=True, squeeze=False)
    for k, (name, r) in enumerate(results.items()):
        _tension_panel(ax[0, k], r, f"{name}: slack {r.slack_time:.2f} s, over-tension "
                                    f"{max(r.worst_over_tension, 0):.1f} N")
        ax[1, k].plot(r.times, 1e3 * r.tracking_error, c="k", lw=1)
        ax[1, k].set_ylabel("tracking error (mm)")
        ax[1, k].set_xlabel("time (s)")
        ax[1, k].set_title(f"max {1e3 * r.tracking_error.max():.2f} mm", fontsize=9)
        for a in ax[:, k]:
            a.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=130)
        plt.close(fig)
    return fig


def _base_outlines(robot: CableRobot, base_poses: np.ndarray) -> list[np.ndarray]:
    """Closed wheel footprints on the ground, (T, p + 1, 3) per base with one, in m, with
    the bases at ``base_poses`` (T, K, 3) (x, y, theta of each base frame)."""
    out = []
    for k, b in enumerate(robot.bases):
        if b.footprint is None:
            continue
        fp = np.asarray(b.footprint, float)
        fp = np.vstack([fp, fp[:1]])
        th = base_poses[:, k, 2, None]
        x = base_poses[:, k, 0, None] + np.cos(th) * fp[:, 0] - np.sin(th) * fp[:, 1]
        y = base_poses[:, k, 1, None] + np.sin(th) * fp[:, 0] + np.cos(th) * fp[:, 1]
        out.append(np.stack([x, y, np.zeros_like(x)], axis=-1))
    return out


def _posts(ex: np.ndarray) -> np.ndarray:
    """Vertical posts from the ground to each exit point (m, 3) as one NaN-separated
    polyline (3 m, 3)."""
    ground = ex * [1.0, 1.0, 0.0]
    gap = np.full_like(ex, np.nan)
    return np.stack([ground, ex, gap], axis=1).reshape(-1, 3)


def animate_control(robot: CableRobot, r: ControlResult, path: str | Path, *,
                    frames: int = 60, fps: int = 15) -> None:
    """3D animated GIF (Pillow): platform box (its attachment points), cables coloured by
    tension (red when outside the limits), the bases (wheel footprints on the ground and
    posts up to their exit points) moving with their poses."""
    idx = np.unique(np.linspace(0, len(r.times) - 1, frames).round().astype(int))
    R = rotation_matrices(r.poses[idx, 3:])
    att = r.poses[idx, None, :3] + np.einsum("tij,mj->tmi", R, robot.attach_local)
    ex = moved_exits(robot, r.base_poses[idx])
    outlines = _base_outlines(robot, r.base_poses[idx])
    fig = plt.figure(figsize=(7, 5))
    ax = fig.add_subplot(projection="3d")
    lo, hi = robot.bounds
    pts = np.concatenate([o.reshape(-1, 3) for o in outlines] + [ex.reshape(-1, 3)])
    ax.set_xlim(min(lo[0], pts[:, 0].min()), max(hi[0], pts[:, 0].max()))
    ax.set_ylim(min(lo[1], -1.5, pts[:, 1].min()), max(hi[1], 1.5, pts[:, 1].max()))
    ax.set_zlim(0.0, hi[2])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    lines = [ax.plot([], [], [], lw=1)[0] for _ in range(robot.m)]
    plat = ax.plot([], [], [], "s", c="k", ms=3)[0]
    exits = ax.plot([], [], [], "^", c="tab:blue", ms=4, label="cable exits")[0]
    feet = [ax.plot([], [], [], c="0.25", lw=1.2, label="base footprint" if k == 0 else None)[0]
            for k in range(len(outlines))]
    posts = ax.plot([], [], [], c="0.45", lw=1.0, label="base posts")[0]
    ax.plot(r.reference[:, 0], r.reference[:, 1], r.reference[:, 2], c="0.6", lw=0.8, ls="--",
            label="reference")
    ax.legend(fontsize=6, loc="upper left")
    title = ax.set_title("")

    def update(f: int):
        k = idx[f]
        t = r.tensions[k]
        for j, ln in enumerate(lines):
            seg = np.stack([ex[f, j], att[f, j]])
            ln.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
            bad = t[j] < r.t_min[j] or t[j] > r.t_max[j]
            ln.set_color("tab:red" if bad else "tab:green")
        plat.set_data_3d(att[f, :, 0], att[f, :, 1], att[f, :, 2])
        exits.set_data_3d(ex[f, :, 0], ex[f, :, 1], ex[f, :, 2])
        for ln, outline in zip(feet, outlines):
            ln.set_data_3d(outline[f, :, 0], outline[f, :, 1], outline[f, :, 2])
        pp = _posts(ex[f])
        posts.set_data_3d(pp[:, 0], pp[:, 1], pp[:, 2])
        title.set_text(f"t = {r.times[k]:.2f} s, error {1e3 * r.tracking_error[k]:.1f} mm")
        return (*lines, plat, exits, *feet, posts, title)

    anim = FuncAnimation(fig, update, frames=len(idx), blit=False)
    save_animation(anim, path, fps=fps)
    plt.close(fig)
