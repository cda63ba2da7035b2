"""Workspace figures coloured by the binding condition (tension limits, tipping, sliding),
as a 2D slice or a 3D view, with the desired workspace box."""

from __future__ import annotations

from itertools import product
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cdpr.model.robot import CableRobot  # noqa: E402
from ..cdpr.workspace.wrench_feasible import WorkspaceResult  # noqa: E402
from ._save import save_figure  # noqa: E402

__all__ = ["plot_binding"]

_STYLE = {"": ("tab:blue", "feasible"), "limits": ("0.8", "tension limits bind"),
          "tipping": ("tab:orange", "tipping binds"), "sliding": ("tab:red", "sliding binds"),
          "exits_box": ("tab:purple", "platform leaves the exits' box")}


def _box_edges(box: np.ndarray) -> list[np.ndarray]:
    corners = np.array(list(product(*zip(box[0], box[1]))))
    edges = []
    for a, b in product(range(8), range(8)):
        if a < b and np.sum(corners[a] != corners[b]) == 1:
            edges.append(corners[[a, b]])
    return edges


def plot_binding(result: WorkspaceResult, robot: CableRobot, path: str | Path | None = None,
                 *, title: str | None = None, view: str = "auto") -> Any:
    """Scatter the workspace points coloured by ``result.binding``.

    Parameters
    ----------
    result : WorkspaceResult
        From :func:`taut.cdpr.wrench_feasible_workspace` (m).
    robot : CableRobot
        Draws its exit points and desired workspace box.
    path : str or Path, optional
        Where to save the figure (PNG, 150 dpi).
    view : {"auto", "slice", "3d"}
        ``"auto"``: a 2D slice when one axis of the points is flat, else 3D.

    Returns
    -------
    matplotlib.figure.Figure
    """
    pts = result.points
    binding = result.binding if result.binding is not None else np.full(len(pts), "")
    flat = [k for k in range(3) if np.ptp(pts[:, k]) == 0.0]
    three_d = view == "3d" or (view == "auto" and not flat)
    fig = plt.figure(figsize=(9, 5.2))
    ax: Any = fig.add_subplot(111, projection="3d") if three_d else fig.add_subplot(111)
    i, j = ([k for k in range(3) if k != flat[0]][:2] if flat else (0, 2))
    for key, (color, name) in _STYLE.items():
        sel = binding == key
        if not sel.any():
            continue
        label = f"{name} ({int(sel.sum())})"
        size = 3 if key == "limits" else 14
        if three_d:
            ax.scatter(pts[sel, 0], pts[sel, 1], pts[sel, 2], s=size, color=color, label=label,
                       alpha=0.6 if key else 0.8)
        else:
            ax.scatter(pts[sel, i], pts[sel, j], s=size, color=color, label=label)
    ex = robot.exits_world
    dw = robot.desired_workspace
    if three_d:
        ax.scatter(ex[:, 0], ex[:, 1], ex[:, 2], marker="v", color="0.2", s=20)
        if dw is not None:
            for e in _box_edges(dw):
                ax.plot(e[:, 0], e[:, 1], e[:, 2], color="tab:green", ls="--", lw=1)
        ax.set_zlabel("z [m]")
        ax.set_ylabel("y [m]")
    else:
        ax.scatter(ex[:, i], ex[:, j], marker="v", color="0.2", s=20)
        if dw is not None:
            lo, hi = dw
            ax.add_patch(plt.Rectangle((float(lo[i]), float(lo[j])), hi[i] - lo[i],
                                       hi[j] - lo[j], fill=False, ls="--",
                                       color="tab:green", label="desired workspace"))
        ax.set_aspect("equal")
        ax.set_ylabel(f"{'xyz'[j]} [m]")
    ax.set_xlabel(f"{'xyz'[i]} [m]" if not three_d else "x [m]")
    ax.set_title(title or f"{robot.name}: binding condition per position", fontsize=10)
    ax.legend(fontsize=7, loc="upper center", ncol=3,
              bbox_to_anchor=(0.5, -0.08 if three_d else -0.14))
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=150)
    return fig
