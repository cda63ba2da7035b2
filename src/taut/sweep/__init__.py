"""Parameter studies at scale: sweep files, chunked execution on Dask (or serially), and
results as Parquet tables.

A sweep names a task (:data:`TASKS`: ``fk_stability_map``, ``plan_suite``,
``plan_robustness``, ``cdpr_workspace``, ``cdpr_deployment``), a base scenario or model, the
parameters and the outputs to keep. :func:`run_sweep` evaluates it chunk by chunk; the
chunks depend only on the sweep, so the rows are the same whatever the number of workers,
and a resumed run skips the chunks already stored.

Examples
--------
>>> import numpy as np
>>> from taut.sweep import Parameter, SweepSpec, evaluate_chunk
>>> from taut.sweep.points import expand
>>> spec = SweepSpec("plan_suite", (Parameter("scenario_seed", values=np.arange(3.0)),))
>>> expand(spec)["scenario_seed"]
array([0., 1., 2.])
"""

from .runner import SweepResult, chunk_size_of, evaluate_chunk, run_sweep
from .spec import Parameter, SweepSpec
from .tasks import TASKS, Task

__all__ = ["TASKS", "Task", "Parameter", "SweepSpec", "SweepResult", "run_sweep",
           "evaluate_chunk", "chunk_size_of"]
