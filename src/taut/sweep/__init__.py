"""Parameter studies at scale: sweep files, chunked execution on Dask (or serially), and
results as Parquet tables.

A sweep names a task (:data:`TASKS`: ``fk_stability_map``, ``plan_suite``,
``plan_robustness``, ``cdpr_workspace``, ``cdpr_deployment``), a base scenario or model, the
parameters and the outputs to keep. :func:`run_sweep` evaluates it chunk by chunk; the
chunks depend only on the sweep, so the rows are the same whatever the number of workers,
and a resumed run skips the chunks already stored.

Sweep files
    :func:`load_sweep` reads and validates a sweep file (YAML or JSON),
    :func:`sweep_from_mapping` an already parsed one; both return a :class:`SweepSpec` of
    :class:`Parameter` values.
Tasks
    :data:`TASKS` maps each task name to its :class:`Task` (parameters, outputs, base).
Running
    :func:`run_sweep` writes ``results.parquet`` and returns a :class:`SweepResult`;
    :func:`evaluate_chunk` computes one chunk's rows, :func:`chunk_size_of` its size.
Results
    :func:`read_results` reads a results folder back as numpy columns and metadata (only
    the columns and rows asked for), :func:`iter_results` batch by batch,
    :func:`results_columns` names its columns, metadata and row count.

Examples
--------
>>> import numpy as np
>>> from taut.sweep import Parameter, SweepSpec, evaluate_chunk
>>> from taut.sweep.points import expand
>>> spec = SweepSpec("plan_suite", (Parameter("scenario_seed", values=np.arange(3.0)),))
>>> expand(spec)["scenario_seed"]
array([0., 1., 2.])
"""

from .file import load_sweep, sweep_from_mapping
from .registry import TASKS
from .results import iter_results, read_results, results_columns
from .runner import SweepResult, chunk_size_of, evaluate_chunk, run_sweep
from .spec import Parameter, SweepSpec
from .task import Task

__all__ = [
    # sweep files
    "load_sweep", "sweep_from_mapping", "SweepSpec", "Parameter",
    # tasks
    "TASKS", "Task",
    # running
    "run_sweep", "SweepResult", "evaluate_chunk", "chunk_size_of",
    # results
    "read_results", "iter_results", "results_columns",
]
