"""Typed exceptions of taut.

Every failure a user can cause derives from :class:`TautError`, so callers catch one base
class and never parse messages. Each error names the offending input in ``field`` (a
parameter name such as ``"formation"``, or a dotted path into a scenario file such as
``"sheet[2]"``) and carries a one-line human ``problem``. ``str(err)`` is
``"<field>: <problem>"``; the CLI prints exactly that line and exits with code 2.
"""

from __future__ import annotations

import importlib

#: Top-level modules of the optional extras -> the extra that installs them.
EXTRAS = {"mujoco": "physics", "dask": "sweep", "distributed": "sweep", "pyarrow": "sweep",
          "starlette": "app", "uvicorn": "app", "ompl": "plan-ompl",
          "selenium": "app-test", "matplotlib": "viz"}

__all__ = [
    "TautError",
    "InvalidInputError",
    "InvalidSheetError",
    "InfeasibleFormationError",
    "ScenarioError",
    "InvalidTrajectoryError",
    "InvalidModelError",
    "InfeasiblePoseError",
    "PlanningError",
    "SweepError",
    "MissingExtraError",
    "EXTRAS",
    "require_extra",
]


class TautError(Exception):
    """Base class of every error taut raises on purpose.

    Parameters
    ----------
    field : str
        Name of the input at fault (parameter name or dotted path in a file).
    problem : str
        One line saying what is wrong with it.
    """

    def __init__(self, field: str, problem: str) -> None:
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}")


class InvalidInputError(TautError, ValueError):
    """An argument has the wrong shape, type, or a non-finite or out-of-range value."""


class InvalidSheetError(InvalidInputError):
    """The sheet polygon is not a valid convex polygon (non-convex, self-intersecting,
    repeated or collinear-degenerate vertices, fewer than 3 vertices)."""


class InfeasibleFormationError(TautError):
    """Two robots stand farther apart than their sheet vertices allow.

    The sheet is inelastic, so robots ``i`` and ``j`` can be at most ``|v_i - v_j|`` apart
    (FK paper, ``FormationFeasible`` in Algorithm 1). ``pair`` holds the 0-based indices and
    ``step`` the trajectory step when raised during a simulation.
    """

    def __init__(self, field: str, problem: str, pair: tuple[int, int],
                 step: int | None = None) -> None:
        self.pair = pair
        self.step = step
        super().__init__(field, problem)


class ScenarioError(InvalidInputError):
    """A scenario or model file is missing, unreadable, malformed or has unknown keys."""


class InvalidTrajectoryError(InvalidInputError):
    """A time series of formations is malformed (width, time stamps, NaN)."""


class InvalidModelError(InvalidInputError):
    """A cable-robot model is inconsistent (missing points, tension limits, footprints)."""


class InfeasiblePoseError(TautError):
    """A platform pose lies outside what the cable robot model can represent."""


class PlanningError(TautError):
    """A planning problem is ill-posed (start or goal blocked, overlapping obstacles)."""


class SweepError(InvalidInputError):
    """A sweep file or run request is invalid: unknown task, parameter or output, an empty
    range, a scheduler that does not answer, an output folder holding another sweep."""


class MissingExtraError(TautError, ImportError):
    """An optional dependency is not installed. ``field`` is its top-level module (e.g.
    ``"mujoco"``) and ``extra`` the extra of taut that installs it (:data:`EXTRAS`); the
    problem is the one line ``not installed; install taut[physics] (pip install
    'taut[physics]')``. Also an ``ImportError``, which it replaces."""

    def __init__(self, module: str) -> None:
        top = module.split(".")[0]
        self.extra = EXTRAS.get(top, top)
        super().__init__(top, f"not installed; install taut[{self.extra}] (pip install "
                              f"'taut[{self.extra}]')")
        self.name = top                         # ImportError's: the module not found


def require_extra(module: str) -> None:
    """Import ``module`` (one of an optional extra's) at an entry point of the library,
    before any work, so its absence is a :class:`MissingExtraError` naming the extra
    instead of a ``ModuleNotFoundError`` from deep inside a call."""
    try:
        importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(module) from None
