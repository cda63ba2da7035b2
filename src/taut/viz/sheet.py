"""Figures of sheet-carrying teams (matplotlib): 3D views of FK equilibria in the style of
the FK paper's Figs. 4-6."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from matplotlib.lines import Line2D  # noqa: E402

from ..sheet.fk.results import Equilibrium, FKResult  # noqa: E402
from ._save import save_figure  # noqa: E402

__all__ = ["draw_equilibrium", "plot_fk", "KIND_COLOURS"]

KIND_COLOURS = {"stable": "tab:green", "saddle": "tab:orange", "not_equilibrium": "tab:red"}


def sheet_unit(units: str | None) -> str:
    """The length unit every sheet figure prints: the scenario's ``units:`` (e.g. ``mm``),
    else ``sheet units`` (sheets take any consistent length unit)."""
    return units or "sheet units"


def legend_handles() -> list[Line2D]:
    """Legend entries of :func:`draw_equilibrium`'s marks."""
    obj = [Line2D([], [], ls="none", marker="o", ms=7, mec="k", color=c,
                  label=f"object: {k.replace('_', ' ')}") for k, c in KIND_COLOURS.items()]
    return [Line2D([], [], color="tab:blue", lw=1.6, label="taut cable"),
            Line2D([], [], color="tab:blue", lw=0.8, ls=":", label="slack cable"),
            Line2D([], [], color="0.55", lw=0.8, ls="--", label="formation at hold height"),
            Line2D([], [], ls="none", marker="s", ms=5, color="0.2", label="robot (ground)"),
            *obj]


def draw_equilibrium(ax: Any, formation: np.ndarray, hold_height: float, e: Equilibrium, *,
                     units: str | None = None) -> None:
    """Draw one rest state on a 3D axis.

    Robots stand on the ground with rods up to their holding points; taut virtual cables
    are solid, slack ones dotted (drawn straight from holding point to object, at most as
    long as the virtual cable); the formation polygon is dashed at the holding height and
    the robots of the taut set are joined by a thin line (their polygon).
    """
    n = len(formation)
    hold = np.column_stack([formation, np.full(n, hold_height)])
    loop = np.vstack([hold, hold[:1]])
    ax.plot(loop[:, 0], loop[:, 1], loop[:, 2], "--", color="0.55", lw=0.8)
    for i, (x, y) in enumerate(formation):
        ax.plot([x, x], [y, y], [0, hold_height], color="0.35", lw=1.2)
        ax.text(x, y, hold_height * 1.04, str(i + 1), fontsize=8, ha="center")
    ax.scatter(formation[:, 0], formation[:, 1], np.zeros(n), marker="s", s=18, color="0.2")
    ax.scatter(hold[:, 0], hold[:, 1], hold[:, 2], s=10, color="0.2")
    taut = set(e.taut)
    for i in range(n):
        seg = np.vstack([hold[i], e.object])
        style = dict(color="tab:blue", lw=1.6) if i in taut else dict(color="tab:blue", lw=0.8, ls=":")
        ax.plot(seg[:, 0], seg[:, 1], seg[:, 2], **style)
    if len(e.taut) >= 3:
        sub = formation[list(e.taut)]
        c = sub.mean(axis=0)
        order = np.argsort(np.arctan2(sub[:, 1] - c[1], sub[:, 0] - c[0]))
        poly = np.vstack([sub[order], sub[order][:1]])
        ax.plot(poly[:, 0], poly[:, 1], np.zeros(len(poly)), color="tab:blue", lw=0.6, alpha=0.6)
    ax.scatter(*e.object, s=60, color=KIND_COLOURS[e.kind], edgecolor="k", zorder=5)
    ax.plot([e.object[0]] * 2, [e.object[1]] * 2, [0, e.object[2]], color="0.7", lw=0.6)
    label = "{" + ",".join(str(i + 1) for i in e.taut) + "}"
    ax.set_title(f"taut {label}: {e.kind.replace('_', ' ')}\n"
                 f"z_o = {e.object[2]:.4g} {sheet_unit(units)}", fontsize=9)
    ax.set_zlim(0, hold_height * 1.08)
    span = np.ptp(formation, axis=0)
    ax.set_box_aspect((max(span[0], 1e-9), max(span[1], 1e-9), hold_height * 1.08))
    unit = f" [{sheet_unit(units)}]"
    ax.set_xlabel("x" + unit, fontsize=8)
    ax.set_ylabel("y" + unit, fontsize=8)
    ax.set_zlabel("z" + unit, fontsize=8)
    ax.tick_params(labelsize=7)


def _lift_above(fig: Any, legend: Any) -> None:
    """Raise the panels' bottom edge until no axis label reaches down into ``legend``
    (tight_layout does not count the labels of 3D axes, drawn outside their boxes)."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    top = legend.get_window_extent(r).y1
    lowest = min((t.get_window_extent(r).y0 for ax in fig.axes
                  for t in (ax.xaxis.label, ax.yaxis.label) if t.get_text()), default=top)
    if lowest < top + 2:
        shift = (top + 2 - lowest) / fig.bbox.height
        bottom = fig.subplotpars.bottom
        fig.subplots_adjust(bottom=min(bottom + shift, fig.subplotpars.top - 0.05))


def plot_fk(result: FKResult, path: str | Path | None = None, *, units: str | None = None,
            title: str | None = None, max_panels: int = 12) -> Any:
    """One 3D panel per equilibrium, stable ones first, with a legend of the marks; returns
    the figure and writes it to ``path`` (PNG/PDF/SVG by extension) when given.

    At most ``max_panels`` states are drawn; when there are more, the figure says how many
    were left out (the stable ones are always drawn first)."""
    order = sorted(result.equilibria, key=lambda e: (not e.stable, e.kind != "saddle"))
    eqs = order[:max_panels]
    left_out = len(order) - len(eqs)
    k = max(1, len(eqs))
    cols = min(3, k)
    rows = math.ceil(k / cols)
    fig = plt.figure(figsize=(4.2 * cols, 3.9 * rows))
    if not eqs:
        ax = fig.add_subplot(1, 1, 1, projection="3d")
        ax.set_title("no equilibrium (object would touch the ground)")
    for j, e in enumerate(eqs):
        ax = fig.add_subplot(rows, cols, j + 1, projection="3d")
        draw_equilibrium(ax, result.formation, result.hold_height, e, units=units)
    head = title or ""
    if left_out:
        head += (("\n" if head else "") + f"{len(eqs)} of {len(order)} equilibria drawn "
                 f"({left_out} left out; `taut fk --json` lists all)")
    if head:
        fig.suptitle(head, fontsize=10)
    legend = fig.legend(handles=legend_handles(), loc="lower center", ncol=4, fontsize=8,
                        frameon=False)
    fig.canvas.draw()                   # the legend's measured height, not a guess
    below = legend.get_window_extent().height / fig.bbox.height
    fig.tight_layout(rect=(0, below + 0.02, 1, 1))
    _lift_above(fig, legend)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        save_figure(fig, path, dpi=150)
        plt.close(fig)
    return fig
