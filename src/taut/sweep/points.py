"""The points of a sweep, as columns, and their partition into chunks.

Points are a pure function of the spec: grid points in C order of the parameters (first
slowest), or ``samples`` seeded draws (``numpy.random.default_rng(seed)``, parameters drawn
in file order). Chunk ``k`` holds points ``[k c, (k + 1) c)``; the partition depends only on
the spec, never on the number of workers, which makes results reproducible and resumable.
"""

from __future__ import annotations

import numpy as np

from .spec import SweepSpec

__all__ = ["expand", "chunk_bounds", "point_seeds"]


def expand(spec: SweepSpec, start: int = 0, stop: int | None = None) -> dict[str, np.ndarray]:
    """Parameter columns of points ``start..stop-1`` (float64 arrays) plus ``point`` (int64).

    Grid points are computed from their flat index, so any slice costs only its own size.
    """
    total = spec.size
    stop = total if stop is None else min(stop, total)
    index = np.arange(start, stop, dtype=np.int64)
    columns: dict[str, np.ndarray] = {"point": index}
    if spec.mode == "random":
        rng = np.random.default_rng(spec.seed)
        for p in spec.parameters:
            columns[p.name] = p.sample(rng, total)[start:stop]
        return columns
    sizes = [p.values.size for p in spec.parameters if p.values is not None]
    if sizes:
        digits = np.unravel_index(index, sizes)
        for p, d in zip(spec.parameters, digits):
            assert p.values is not None
            columns[p.name] = p.values[d]
    return columns


def chunk_bounds(total: int, chunk_size: int) -> list[tuple[int, int]]:
    """``(start, stop)`` of every chunk of ``total`` points."""
    return [(lo, min(lo + chunk_size, total)) for lo in range(0, total, chunk_size)]


def point_seeds(spec: SweepSpec, points: np.ndarray) -> np.ndarray:
    """A reproducible 64-bit seed per point index, independent of chunking and workers."""
    seq = np.random.SeedSequence([spec.seed, 0x7A57])
    base = int(seq.generate_state(1, dtype=np.uint64)[0])
    return (np.asarray(points, dtype=np.uint64) * np.uint64(0x9E3779B97F4A7C15)
            + np.uint64(base)) & np.uint64(0x7FFFFFFFFFFFFFFF)
