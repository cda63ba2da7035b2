"""Enumerated options of the sheet analyses: the forward-kinematics method and the compute
backend. Each is validated once, at the public entry, with :func:`taut._validate.as_choice`."""

from __future__ import annotations

from typing import Literal

__all__ = ["Method", "METHODS", "Backend", "BACKENDS"]

#: Forward-kinematics algorithm (:func:`taut.sheet.forward_kinematics`).
Method = Literal["fast", "exhaustive", "subsets"]
METHODS: tuple[str, ...] = ("fast", "exhaustive", "subsets")

#: Compute backend of the solvers: ``"auto"`` (the compiled kernels where they apply),
#: ``"numba"`` (insist on them) or ``"numpy"`` (never use them).
Backend = Literal["auto", "numba", "numpy"]
BACKENDS: tuple[str, ...] = ("auto", "numba", "numpy")
