"""The one result convention of taut: every outcome that can fail says so the same way.

Like scipy's ``OptimizeResult`` (``success``, ``status``, ``message``) and CASPR's exit
types, each analysis that can answer "no" to a valid question returns a frozen result with

``success : bool`` (or a boolean array of shape ``(B,)`` for batched results)
    True when the analysis produced what was asked for.
``status : str`` (or an array of str for batched results)
    One of :data:`STATUSES`; ``"ok"`` exactly when ``success`` is true.
``message : str``
    One human line: what was found, or why not.

Exceptions (subclasses of :class:`taut.errors.TautError`) are for invalid input only.
"""

from __future__ import annotations

from typing import Literal

__all__ = ["Status", "STATUSES", "check_status"]

#: Every status value used by a taut result.
Status = Literal[
    "ok",                # the analysis produced what was asked for
    "infeasible",        # no solution satisfies the constraints (e.g. tension limits)
    "not_strict",        # the answer exists but is not strict (e.g. a flat lowest rest state)
    "unreachable",       # a target provably cannot be reached (a certificate is attached)
    "refuted",           # a certificate proves that no solution exists
    "no_route",          # the planner's search space holds no route
    "budget_exhausted",  # the search stopped at its budget without a proof either way
    "not_converged",     # an iterative solver stopped before its tolerance
    "unverified",        # a candidate was found but failed verification
    "diverged",          # a simulation left the model's domain
    "interrupted",       # a run stopped before every point was computed (resumable)
]

STATUSES: tuple[str, ...] = Status.__args__  # type: ignore[attr-defined]


def check_status(status: str) -> str:
    """Return ``status`` if it is a known status value, else raise ``ValueError``.

    Used by result constructors so a misspelt status cannot escape into user code.
    """
    if status not in STATUSES:
        raise ValueError(f"unknown status {status!r}; expected one of {STATUSES}")
    return status

