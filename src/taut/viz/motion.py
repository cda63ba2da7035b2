"""Figures of a quasi-static transport simulation (matplotlib): object height over time with
the events marked, and the top view of the robots' and the object's paths."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..sheet.sim.simulate import SimulationResult  # noqa: E402
from ._save import save_figure  # noqa: E402
from .sheet import sheet_unit  # noqa: E402

__all__ = ["plot_simulation"]

_MARKERS = {"jump": ("v", "tab:red"), "taut_change": ("|", "tab:gray"),
            "lost": ("x", "black"), "recovered": ("^", "tab:green")}


def plot_simulation(result: SimulationResult, path: str | Path | None = None, *,
                    time: np.ndarray | None = None, units: str | None = None,
                    title: str | None = None, time_unit: str = "s") -> Any:
    """Two panels: :math:`z_o(t)` with events, and the top view of all paths.

    The height axis spans the object's heights only (the hold height is written in the
    panel, not drawn), so a jump of a few mm on a 1 m stage stays visible.

    Parameters
    ----------
    result : SimulationResult
    path : str or Path, optional
        Write the figure there (format from the suffix) and close it; otherwise return it.
    time : ndarray, shape (T,), optional
        Time stamps (default: step index).
    units : str, optional
        Length unit label.
    title : str, optional
    time_unit : str
        Label of the time stamps' unit (the trajectory file's; default s).

    Returns
    -------
    matplotlib.figure.Figure or None
    """
    T = len(result)
    t = np.arange(T) if time is None else np.asarray(time, dtype=float)
    u = f" [{sheet_unit(units)}]"
    fig, (ax_h, ax_xy) = plt.subplots(1, 2, figsize=(12, 5))
    ax_h.plot(t, result.object[:, 2], color="tab:blue", lw=1.5, label="object height $z_o$")
    seen = set()
    for e in result.events:
        marker, colour = _MARKERS[e.kind]
        k = min(e.step, T - 1)
        tk = t[k - 1] + e.fraction * (t[k] - t[k - 1]) if k > 0 else t[0]
        z = e.object_after[2] if np.isfinite(e.object_after[2]) else e.object_before[2]
        label = None if e.kind in seen else e.kind.replace("_", " ")
        seen.add(e.kind)
        ax_h.plot([tk], [z], marker=marker, color=colour, ms=9, ls="none", label=label)
        if e.kind == "jump":
            ax_h.vlines(tk, e.object_after[2], e.object_before[2], colors=colour, lw=1)
    ax_h.set_xlabel(f"time [{time_unit}]" if time is not None else "step (no time stamps)")
    ax_h.set_ylabel(f"object height $z_o${u}")
    z = result.object[:, 2]
    z = z[np.isfinite(z)]
    if z.size:
        lo, hi = float(z.min()), float(z.max())
        pad = max(0.08 * (hi - lo), 1e-3 * max(abs(hi), 1.0))
        ax_h.set_ylim(lo - pad, hi + pad)
    unit_word = f" {sheet_unit(units)}"
    ax_h.set_title(f"hold height $z_r$ = {result.hold_height:g}{unit_word}", fontsize=9)
    ax_h.legend(loc="best", fontsize=8)
    ax_h.grid(alpha=0.3)

    R = result.formations
    cmap = plt.get_cmap("tab10")
    for i in range(R.shape[1]):
        c = cmap(i % 10)
        ax_xy.plot(R[:, i, 0], R[:, i, 1], color=c, lw=1)
        ax_xy.plot(R[0, i, 0], R[0, i, 1], "o", color=c, ms=5)
        ax_xy.annotate(str(i + 1), R[-1, i], color=c, fontsize=9, xytext=(3, 3),
                       textcoords="offset points")
    for k, style in ((0, ":"), (T - 1, "-")):
        poly = np.vstack([R[k], R[k][:1]])
        ax_xy.plot(poly[:, 0], poly[:, 1], style, color="0.5", lw=0.8)
    ax_xy.plot(result.object[:, 0], result.object[:, 1], color="k", lw=2, label="object")
    for e in result.jumps:
        ax_xy.annotate("", e.object_after[:2], e.object_before[:2],
                       arrowprops=dict(arrowstyle="->", color="tab:red"))
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel(f"x{u}")
    ax_xy.set_ylabel(f"y{u}")
    ax_xy.set_title("top view (dots: start, dotted/solid: first/last formation)", fontsize=9)
    ax_xy.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=120)
        plt.close(fig)
        return None
    return fig
