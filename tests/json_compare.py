"""Comparison of JSON documents for the examples' recorded outputs (shared by tests)."""

from __future__ import annotations

import math

import pytest


def assert_same_document(got, want, where="$"):
    """Recursive equality: exact for str/bool/None/int and keys, floats within 1e-9
    relative (1e-9 absolute near zero), NaN equal to NaN."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and set(got) == set(want), \
            f"{where}: keys {sorted(got) if isinstance(got, dict) else got} != {sorted(want)}"
        for k in want:
            assert_same_document(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{where}: length differs"
        for i, (g, w) in enumerate(zip(got, want)):
            assert_same_document(g, w, f"{where}[{i}]")
    elif isinstance(want, bool) or want is None or isinstance(want, str):
        assert got == want and type(got) is type(want), f"{where}: {got!r} != {want!r}"
    elif isinstance(want, (int, float)):
        assert isinstance(got, (int, float)) and not isinstance(got, bool), f"{where}: {got!r}"
        if isinstance(want, float) and math.isnan(want):
            assert math.isnan(got), f"{where}: {got} != nan"
        else:
            assert got == pytest.approx(want, rel=1e-9, abs=1e-9), f"{where}: {got} != {want}"
    else:  # pragma: no cover - JSON has no other types
        raise AssertionError(f"{where}: unexpected type {type(want)}")
