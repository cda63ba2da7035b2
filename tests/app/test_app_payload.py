"""The app's request decoding (taut.app.payload) checks bodies of millions of numbers in
the memory their parsed JSON already takes: a walk that queued one entry per number took
a worker from 0.15 to 0.47 GiB on an 8 MiB body of zeros and made the app's worst case
exceed its ~1 GB bound (issue 24)."""

import tracemalloc

import numpy as np
import pytest

from taut.app.payload import check_json, numbers
from taut.errors import InvalidInputError

#: Numbers in the long body: at 250,000 check_json peaks at 2.6 MB under its 4.0 MB bound and
#: a walk queueing one entry per number at 37 MB (1,000,000 cost 1.9 s more CPU).
N = 250_000


def traced_peak(fn):
    """Peak bytes Python allocated while ``fn()`` ran (tracemalloc)."""
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def refused(fn):
    try:
        fn()
    except InvalidInputError as exc:
        return str(exc)
    raise AssertionError("accepted")


def test_a_long_flat_body_is_walked_in_constant_extra_memory():
    raw = b'{"formations": [[' + b"0," * (N - 1) + b"0]]}"
    body = check_json(raw)
    # the parsed list holds N pointers (8 bytes each); a walk with one tuple per number
    # would need ~7x that on top
    assert traced_peak(lambda: check_json(raw)) < 8 * N + len(raw) * 2 + 2**20
    message = []
    peak = traced_peak(lambda: message.append(refused(
        lambda: numbers(body["formations"], "formations", 3))))
    assert peak < 2**20
    assert message == ["formations: must be a list of lists of lists of numbers"]


@pytest.mark.parametrize("value, ndim, ok", [
    ([[1, 2.5], [3, 4]], 2, True), ([[1, 2], [3]], 2, False), ([[1, True]], 2, False),
    ([[[1, 2]], [[3, 4]]], 3, True), ([[[1, 2]], [3, 4]], 3, False), ([], 1, True),
    ([[]], 2, True), ([[1, "2"]], 2, False), ([1, [2]], 1, False), ([[1], 2], 2, False)])
def test_numbers_accepts_exactly_regular_nested_lists_of_numbers(value, ndim, ok):
    if ok:
        assert np.array_equal(numbers(value, "x", ndim), np.asarray(value, dtype=float))
    else:
        assert refused(lambda: numbers(value, "x", ndim)).startswith("x: must be")
