"""The points of a sweep, as columns, and their partition into chunks.

Points are a pure function of the spec: grid points in C order of the parameters (first
slowest), or ``samples`` seeded draws (``numpy.random.default_rng(seed)``, parameters drawn
in file order). Chunk ``k`` holds points ``[k c, (k + 1) c)``; the partition depends only on
the spec, never on the number of workers, which makes results reproducible and resumable.

Nothing here holds the whole sweep: grid points come from their flat index, and random
draws are made piece by piece (numpy's generators give the same stream whether ``n`` values
are drawn at once or in consecutive pieces), so memory is that of one chunk.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Iterator, Mapping
from typing import Any, cast

import numpy as np

from .spec import Parameter, SweepSpec

__all__ = ["expand", "chunk_bounds", "chunk_columns", "chunk_streams", "point_seeds"]

#: Values drawn at a time while skipping through a random stream.
_PIECE = 1 << 16


def _skip(p: Parameter, rng: np.random.Generator, count: int) -> None:
    """Advance ``rng`` past ``count`` draws of ``p`` in bounded pieces."""
    while count > 0:
        n = min(count, _PIECE)
        p.sample(rng, n)
        count -= n


def _streams(spec: SweepSpec) -> list[np.random.Generator]:
    """One generator per parameter, positioned at that parameter's first draw (parameter
    ``j`` draws after all ``spec.size`` draws of parameters ``0..j-1``)."""
    rng = np.random.default_rng(spec.seed)
    streams = []
    for p in spec.parameters:
        streams.append(copy.deepcopy(rng))
        _skip(p, rng, spec.size)
    return streams


def expand(spec: SweepSpec, start: int = 0, stop: int | None = None,
           states: tuple[Mapping[str, Any], ...] | None = None) -> dict[str, np.ndarray]:
    """Parameter columns of points ``start..stop-1`` (float64 arrays) plus ``point`` (int64).

    Grid points are computed from their flat index, so any slice costs only its own size.
    Random draws skip through the draws before ``start`` (in bounded pieces), unless
    ``states`` gives the generators' states at ``start`` (:func:`chunk_streams`).
    """
    total = spec.size
    stop = total if stop is None else min(stop, total)
    index = np.arange(start, stop, dtype=np.int64)
    columns: dict[str, np.ndarray] = {"point": index}
    if spec.mode == "random":
        if states is None:
            gens = _streams(spec)
            for p, rng in zip(spec.parameters, gens):
                _skip(p, rng, start)
        else:
            gens = [_generator(state) for state in states]
        for p, rng in zip(spec.parameters, gens):
            columns[p.name] = p.sample(rng, max(stop - start, 0))
        return columns
    sizes = [p.values.size for p in spec.parameters if p.values is not None]
    if sizes:
        digits = np.unravel_index(index, sizes)
        for p, d in zip(spec.parameters, digits):
            assert p.values is not None
            columns[p.name] = p.values[d]
    return columns


def _generator(state: Mapping[str, Any]) -> np.random.Generator:
    """A generator in ``state`` (a ``bit_generator.state`` of :func:`chunk_streams`)."""
    bits = np.random.PCG64()
    bits.state = cast(Any, state)
    return np.random.Generator(bits)


def chunk_bounds(total: int, chunk_size: int, stop: int | None = None
                 ) -> list[tuple[int, int]]:
    """``(start, stop)`` of every chunk of ``total`` points (only those starting before
    ``stop`` when given: a run limited to its first points lists no other chunk)."""
    end = total if stop is None else min(stop, total)
    return [(lo, min(lo + chunk_size, total)) for lo in range(0, end, chunk_size)]


def chunk_streams(spec: SweepSpec, bounds: Iterable[tuple[int, int]]
                  ) -> Iterator[tuple[Mapping[str, Any], ...] | None]:
    """Per chunk of ``bounds``, what :func:`expand` needs to draw its random columns without
    going through the points before it: the state of each parameter's generator at the
    chunk's first point (a few hundred bytes; None for a grid). Consecutive bounds from 0
    (as :func:`chunk_bounds` gives) cost one pass over the sweep's draws in all."""
    if spec.mode != "random":
        for _ in bounds:
            yield None
        return
    streams, at = _streams(spec), 0
    for lo, hi in bounds:
        hi = min(hi, spec.size)
        if lo != at:                         # not consecutive: position the streams anew
            streams = _streams(spec)
            for p, rng in zip(spec.parameters, streams):
                _skip(p, rng, lo)
        yield tuple(rng.bit_generator.state for rng in streams)
        for p, rng in zip(spec.parameters, streams):
            _skip(p, rng, hi - lo)
        at = hi


def chunk_columns(spec: SweepSpec, bounds: Iterable[tuple[int, int]]
                  ) -> Iterator[dict[str, np.ndarray]]:
    """:func:`expand` of each of ``bounds`` in turn (see :func:`chunk_streams`)."""
    bounds = list(bounds)
    for (lo, hi), states in zip(bounds, chunk_streams(spec, bounds)):
        yield expand(spec, lo, hi, states)


def point_seeds(spec: SweepSpec, points: np.ndarray) -> np.ndarray:
    """A reproducible 64-bit seed per point index, independent of chunking and workers."""
    seq = np.random.SeedSequence([spec.seed, 0x7A57])
    base = int(seq.generate_state(1, dtype=np.uint64)[0])
    return (np.asarray(points, dtype=np.uint64) * np.uint64(0x9E3779B97F4A7C15)
            + np.uint64(base)) & np.uint64(0x7FFFFFFFFFFFFFFF)
