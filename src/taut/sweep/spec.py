"""The validated sweep model: which task, over which parameters, keeping which outputs.

A :class:`SweepSpec` is immutable and fully resolved (base file paths absolute, parameter
values as float64 arrays or distributions), so that two equal specs describe exactly the same
table of points. Its :attr:`~SweepSpec.digest` identifies the sweep in a results folder.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._validate import as_choice
from ..errors import InvalidInputError, SweepError
from .._repr import CompactRepr

__all__ = ["Parameter", "SweepSpec", "Distribution", "DISTRIBUTIONS"]

Distribution = Literal["uniform", "normal", "integers", "choice"]
DISTRIBUTIONS: tuple[str, ...] = ("uniform", "normal", "integers", "choice")


def _choice(value: Any, choices: Any, field: str) -> str:
    """:func:`taut._validate.as_choice`, failing with a :class:`~taut.errors.SweepError`."""
    try:
        return as_choice(value, choices, field)
    except InvalidInputError as exc:
        raise SweepError(exc.field, exc.problem) from None


@dataclass(frozen=True, eq=False, repr=False)
class Parameter(CompactRepr):
    """One swept parameter.

    Parameters
    ----------
    name : str
        A parameter the task accepts (see ``taut.sweep.TASKS[task].parameters``).
    values : ndarray, shape (K,), optional
        Grid values (``mode="grid"``), float64, in the parameter's unit.
    distribution : {"uniform", "normal", "integers", "choice"}, optional
        Law of the seeded random samples (``mode="random"``).
    arguments : ndarray, optional
        ``(low, high)`` for uniform and integers (high exclusive for integers),
        ``(mean, std)`` for normal, the candidate values for choice.
    """

    name: str
    values: np.ndarray | None = None
    distribution: str | None = None
    arguments: np.ndarray | None = None

    def __post_init__(self) -> None:
        if (self.values is None) == (self.distribution is None):
            raise SweepError(f"parameters.{self.name}", "give either grid values or a "
                             "random distribution")
        for attr in ("values", "arguments"):
            arr = getattr(self, attr)
            if arr is None:
                continue
            try:
                arr = np.array(arr, dtype=float).reshape(-1)
            except (TypeError, ValueError):
                raise SweepError(f"parameters.{self.name}", f"{attr} must be numbers (a list "
                                 "or array)") from None
            if arr.size == 0:
                raise SweepError(f"parameters.{self.name}", "is empty")
            if not np.all(np.isfinite(arr)):
                raise SweepError(f"parameters.{self.name}", "must be finite numbers")
            arr.setflags(write=False)
            object.__setattr__(self, attr, arr)
        if self.distribution is not None:
            self._check_distribution()

    def _check_distribution(self) -> None:
        _choice(self.distribution, DISTRIBUTIONS, f"parameters.{self.name}")
        where = f"parameters.{self.name}.{self.distribution}"
        a = self.arguments
        assert a is not None
        if self.distribution in ("uniform", "integers", "normal") and a.size != 2:
            raise SweepError(where, "needs exactly two numbers")
        if self.distribution in ("uniform", "integers") and not a[0] < a[1]:
            raise SweepError(where, f"is an empty range [{a[0]:g}, {a[1]:g})")
        if self.distribution == "normal" and a[1] < 0:
            raise SweepError(where, "standard deviation must be >= 0")

    def sample(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """``count`` seeded draws (random mode)."""
        a = self.arguments
        assert a is not None
        if self.distribution == "uniform":
            return rng.uniform(a[0], a[1], count)
        if self.distribution == "normal":
            return rng.normal(a[0], a[1], count)
        if self.distribution == "integers":
            return rng.integers(int(np.ceil(a[0])), int(np.ceil(a[1])), count).astype(float)
        return rng.choice(a, count)

    def canonical(self) -> dict[str, Any]:
        """A JSON-able form used for the sweep's digest."""
        if self.values is not None:
            return {"values": [float(v) for v in self.values]}
        assert self.arguments is not None
        return {self.distribution or "": [float(v) for v in self.arguments]}


@dataclass(frozen=True, eq=False)
class SweepSpec:
    """A validated parameter study.

    Parameters
    ----------
    task : str
        Name of a task in ``taut.sweep.TASKS``.
    parameters : tuple of Parameter
        In grid mode the points are the Cartesian product, first parameter slowest.
    base : str, optional
        Resolved path of the base scenario or model file (for messages), or a preset name.
    base_data : mapping, optional
        The base file, parsed and validated on the client. Workers build the model from it,
        so a remote cluster needs no access to the file (part of the digest).
    mode : {"grid", "random"}
    samples : int
        Number of points in random mode.
    seed : int
        Seed of the random samples and of any per-point randomness (>= 0).
    chunk_size : int
        Points per task sent to a worker (0: the task's default).
    outputs : tuple of str
        Columns to keep besides the parameters (empty: all of the task's outputs).
    options : mapping
        Task options that are not swept (e.g. the workspace grid).
    source : str
        The sweep file's text, stored in the results' metadata.
    """

    task: str
    parameters: tuple[Parameter, ...]
    base: str | None = None
    base_data: Mapping[str, Any] | None = None
    mode: Literal["grid", "random"] = "grid"
    samples: int = 0
    seed: int = 0
    chunk_size: int = 0
    outputs: tuple[str, ...] = ()
    options: Mapping[str, Any] = field(default_factory=dict)
    source: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        """Parameter names, in column order."""
        return tuple(p.name for p in self.parameters)

    @property
    def size(self) -> int:
        """Number of points."""
        if self.mode == "random":
            return int(self.samples)
        total = 1
        for p in self.parameters:
            assert p.values is not None
            total *= p.values.size
        return total

    @property
    def digest(self) -> str:
        """SHA-256 of everything that determines the results (not the file's comments)."""
        payload = {
            "task": self.task, "mode": self.mode, "samples": self.samples, "seed": self.seed,
            "chunk_size": self.chunk_size, "outputs": list(self.outputs),
            "options": self.options, "base": self.base_data if self.base_data is not None else (self.base or ""),
            "parameters": {p.name: p.canonical() for p in self.parameters},
        }
        text = json.dumps(payload, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()
