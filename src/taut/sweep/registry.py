"""Every sweep task by name (:data:`TASKS`)."""

from __future__ import annotations

from .task import Task
from .tasks.cdpr import CDPR_DEPLOYMENT, CDPR_WORKSPACE
from .tasks.fk import FK_STABILITY_MAP
from .tasks.plan import PLAN_ROBUSTNESS, PLAN_SUITE

__all__ = ["TASKS"]

#: The tasks a sweep file may name, by :attr:`Task.name`.
TASKS: dict[str, Task] = {t.name: t for t in (FK_STABILITY_MAP, PLAN_SUITE, PLAN_ROBUSTNESS,
                                              CDPR_WORKSPACE, CDPR_DEPLOYMENT)}
