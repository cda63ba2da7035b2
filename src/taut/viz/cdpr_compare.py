"""Side-by-side workspace slices of several cable robots (e.g. the suspended and the
fully constrained FASTKIT): per position the binding condition as colour, the
wrench-closure workspace as rings, the desired workspace box. Draws results; computes
nothing."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cdpr.model.robot import CableRobot  # noqa: E402
from ..errors import InvalidInputError  # noqa: E402
from ..cdpr.workspace.wrench_feasible import WorkspaceResult  # noqa: E402
from .cdpr import draw_robot_outline  # noqa: E402
from .cdpr_binding import _STYLE  # noqa: E402
from ._save import save_figure  # noqa: E402

__all__ = ["plot_workspace_comparison"]


def _coverage_line(ws: WorkspaceResult) -> str:
    parts = [f"limits {100 * ws.coverage:.1f} %"]
    for name, cov in (("+ tipping", ws.coverage_tipping), ("+ sliding", ws.coverage_sliding),
                      ("+ exits' box", ws.coverage_inside),
                      ("closure", ws.coverage_closure)):
        if cov is not None:
            parts.append(f"{name} {100 * cov:.1f} %")
    return ", ".join(parts)


def plot_workspace_comparison(results: Sequence[WorkspaceResult],
                              robots: Sequence[CableRobot], path: str | Path | None = None,
                              *, titles: Sequence[str] | None = None) -> Any:
    """One panel per robot: a flat workspace grid (a slice, m) coloured by
    ``result.binding``, rings where ``result.closure`` is True.

    Parameters
    ----------
    results : sequence of WorkspaceResult
        From :func:`taut.cdpr.wrench_feasible_workspace` on grids with one flat axis
        (``closure=True`` to draw the wrench-closure workspace).
    robots : sequence of CableRobot
        The robots, in the same order (exit points, bases and desired box are drawn).
    path : str or Path, optional
        Where to save the figure (150 dpi).
    titles : sequence of str, optional
        Panel titles (default: the robots' names).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if len(results) != len(robots) or not results:
        raise InvalidInputError("results", "give one robot per result, at least one")
    fig, axes = plt.subplots(len(results), 1, figsize=(9, 3.6 * len(results)), squeeze=False)
    for k, (ws, robot) in enumerate(zip(results, robots)):
        ax = axes[k, 0]
        pts = ws.points
        flat = [a for a in range(3) if np.ptp(pts[:, a]) == 0.0]
        i, j = [a for a in range(3) if a != (flat[0] if flat else 1)][:2]
        draw_robot_outline(ax, robot, (i, j))
        binding = ws.binding if ws.binding is not None else np.full(len(pts), "")
        for key, (color, name) in _STYLE.items():
            sel = binding == key
            if sel.any():
                ax.scatter(pts[sel, i], pts[sel, j], s=4 if key == "limits" else 16,
                           color=color, label=f"{name} ({int(sel.sum())})")
        if ws.closure is not None and ws.closure.any():
            c = ws.closure
            ax.scatter(pts[c, i], pts[c, j], s=40, facecolors="none", edgecolors="k",
                       linewidths=0.6, label=f"wrench closure ({int(c.sum())})")
        if robot.desired_workspace is not None:
            lo, hi = robot.desired_workspace
            ax.add_patch(plt.Rectangle((float(lo[i]), float(lo[j])), hi[i] - lo[i],
                                       hi[j] - lo[j], fill=False, ls="--", color="tab:green",
                                       label="desired workspace"))
        ax.set_aspect("equal")
        ax.set_xlabel(f"{'xyz'[i]} [m]")
        ax.set_ylabel(f"{'xyz'[j]} [m]")
        head = titles[k] if titles is not None else robot.name
        ax.set_title(f"{head}\n{_coverage_line(ws)}", fontsize=9)
        ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=150)
    return fig
