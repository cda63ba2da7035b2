"""What a sweep task is: the named computation a sweep runs over its points.

A :class:`Task` declares the parameters it accepts (name -> unit and meaning), the output
columns it produces, a default chunk size, the kind of base file it sweeps, how to build
its per-process context from the spec and the base (built once per worker and cached), and
how to evaluate a chunk of points. Tasks never read or write files or print; the runner
does. The tasks themselves live in :mod:`taut.sweep.tasks`, collected in
:data:`taut.sweep.TASKS` (:mod:`taut.sweep.registry`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from .._repr import CompactRepr

__all__ = ["Task", "Columns", "BaseKind"]

#: Chunk columns: name -> one entry per point.
Columns = dict[str, np.ndarray]
#: What a task's ``base`` names ("" when it takes no base file).
BaseKind = Literal["sheet scenario", "plan scenario", "cdpr model", ""]


@dataclass(frozen=True, repr=False)
class Task(CompactRepr):
    """A sweep task.

    Attributes
    ----------
    name : str
    summary : str
        One line for ``taut sweep --help`` and error messages.
    parameters : mapping of str to str
        Accepted parameter names and their meaning (with unit).
    outputs : mapping of str to str
        Output columns and their meaning (with unit).
    defaults : callable
        ``defaults(context) -> mapping``: the value of each parameter that is not swept
        (may depend on the base scenario, e.g. its hold height).
    default_chunk : int
        Points per chunk when the sweep file does not say (chosen so one chunk is roughly
        0.1-1 s of work, against ~1 ms of Dask overhead per task).
    needs_base : {"sheet scenario", "plan scenario", "cdpr model", ""}
        What ``base`` must name ("": the task takes no base file).
    prepare : callable
        ``prepare(spec, base) -> context``, built once per process; ``base`` is the sweep's
        base scenario or model (:func:`taut.sweep.file.base_model`; None without one).
    run : callable
        ``run(context, columns, seeds) -> columns`` for one chunk: parameter columns
        (float64, one entry per point) and per-point seeds in, output columns out.
    """

    name: str
    summary: str
    parameters: Mapping[str, str]
    outputs: Mapping[str, str]
    defaults: Callable[[Any], Mapping[str, float]]
    default_chunk: int
    needs_base: BaseKind
    prepare: Callable[[Any, Any], Any]
    run: Callable[[Any, Columns, np.ndarray], Columns]
