"""The named computations a sweep can run, each calling the existing library.

A :class:`Task` declares the parameters it accepts (name -> unit and meaning), the output
columns it produces, a default chunk size, how to build its per-process context from the
spec (loaded once per worker and cached), and how to evaluate a chunk of points. Tasks
never write files or print; the runner does.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Task", "TASKS", "register"]

Columns = dict[str, np.ndarray]


@dataclass(frozen=True)
class Task:
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
    needs_base : str
        What ``base`` must name: "sheet scenario", "plan scenario", "cdpr model" or "".
    prepare : callable
        ``prepare(spec) -> context``; built once per process.
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
    needs_base: str
    prepare: Callable[[Any], Any]
    run: Callable[[Any, Columns, np.ndarray], Columns]


TASKS: dict[str, Task] = {}


def register(task: Task) -> Task:
    """Add ``task`` to :data:`TASKS`."""
    TASKS[task.name] = task
    return task


def _load_all() -> None:
    from . import cdpr, fk, plan  # noqa: F401  (each module registers its tasks)


_load_all()
