"""Figures of sweep results: a heat map over two parameters, or a curve over one.

Rows sharing the plotted parameters (other parameters swept too) are averaged, which makes a
boolean column a rate (success rate, fraction torn). A text column (a status, the taut
cables of a state) is drawn as categories: each cell shows its most frequent value, with
the values named on the colour bar (or the vertical axis of a curve)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ._save import save_figure

__all__ = ["plot_sweep"]


def _mean_by(keys: list[np.ndarray], values: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    stacked = np.stack(keys, axis=1)
    uniq, inverse = np.unique(stacked, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    ok = np.isfinite(values)
    sums = np.bincount(inverse[ok], weights=values[ok], minlength=len(uniq))
    counts = np.bincount(inverse[ok], minlength=len(uniq))
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
    return [uniq[:, k] for k in range(uniq.shape[1])], mean


def _mode_by(keys: list[np.ndarray], codes: np.ndarray, n: int
             ) -> tuple[list[np.ndarray], np.ndarray]:
    """Most frequent category code per distinct key row (ties: the first category)."""
    stacked = np.stack(keys, axis=1)
    uniq, inverse = np.unique(stacked, axis=0, return_inverse=True)
    counts = np.zeros((len(uniq), n))
    np.add.at(counts, (inverse.reshape(-1), codes), 1.0)
    return [uniq[:, k] for k in range(uniq.shape[1])], np.argmax(counts, axis=1).astype(float)


def plot_sweep(columns: dict[str, np.ndarray], x: str, value: str, path: str | Path, *,
               y: str | None = None, title: str | None = None,
               labels: dict[str, str] | None = None) -> Path:
    """Write a heat map of ``value`` over ``x`` and ``y`` (or a curve over ``x``) to ``path``.

    ``columns`` maps column names to arrays (one entry per row); ``labels`` gives axis
    labels with units (default: the column names).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = labels or {}
    raw = np.asarray(columns[value])
    cats: np.ndarray | None = None
    if raw.dtype.kind in "OSU":                      # text: categories
        cats, codes = np.unique(raw.astype(str), return_inverse=True)
        codes = codes.reshape(-1)
        names = [c if len(c) <= 40 else c[:37] + "..." for c in cats.tolist()]
        names = [n or "(none)" for n in names]

        def aggregate(keys: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
            return _mode_by(keys, codes, len(cats))
    else:
        vals = np.asarray(raw, dtype=float)

        def aggregate(keys: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
            return _mean_by(keys, vals)
    fig, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    if y is None:
        (xs,), mean = aggregate([np.asarray(columns[x], float)])
        ax.plot(xs, mean, marker="o", ms=3, ls="-" if cats is None else "")
        ax.set_ylabel(labels.get(value, value))
        if cats is not None:
            ax.set_yticks(np.arange(len(cats)), names)
    elif cats is not None:
        (xs, ys), mode = aggregate([np.asarray(columns[x], float),
                                    np.asarray(columns[y], float)])
        from matplotlib.colors import BoundaryNorm
        ux, uy = np.unique(xs), np.unique(ys)
        grid = np.full((len(uy), len(ux)), np.nan)
        grid[np.searchsorted(uy, ys), np.searchsorted(ux, xs)] = mode
        n = len(cats)
        mesh_c: Any = ax.pcolormesh(ux, uy, grid, shading="nearest",
                                    cmap=plt.get_cmap("tab20", max(n, 1)),
                                    norm=BoundaryNorm(np.arange(n + 1) - 0.5, max(n, 1)))
        bar = fig.colorbar(mesh_c, ax=ax, ticks=np.arange(n),
                           label=labels.get(value, value) + " (most frequent)")
        bar.ax.set_yticklabels(names)
        ax.set_ylabel(labels.get(y, y))
    else:
        (xs, ys), mean = aggregate([np.asarray(columns[x], float),
                                    np.asarray(columns[y], float)])
        ux, uy = np.unique(xs), np.unique(ys)
        grid = np.full((len(uy), len(ux)), np.nan)
        grid[np.searchsorted(uy, ys), np.searchsorted(ux, xs)] = mean
        finite = grid[np.isfinite(grid)]
        levels = np.unique(finite)
        if levels.size and levels.size <= 10 and np.all(levels == np.round(levels)):
            # A count: one colour per value, ticks on the values.
            from matplotlib.colors import BoundaryNorm
            edges = np.concatenate([levels - 0.5, [levels[-1] + 0.5]])
            cmap = plt.get_cmap("viridis", levels.size)
            mesh: Any = ax.pcolormesh(ux, uy, grid, shading="nearest", cmap=cmap,
                                      norm=BoundaryNorm(edges, levels.size))
            fig.colorbar(mesh, ax=ax, ticks=levels, label=labels.get(value, value))
        else:
            mesh = ax.pcolormesh(ux, uy, grid, shading="nearest", cmap="viridis")
            fig.colorbar(mesh, ax=ax, label=labels.get(value, value))
        ax.set_ylabel(labels.get(y, y))
    ax.set_xlabel(labels.get(x, x))
    ax.set_title(title or f"{value} over {x}" + (f" and {y}" if y else ""))
    out = Path(path)
    save_figure(fig, out, dpi=150)
    plt.close(fig)
    return out
