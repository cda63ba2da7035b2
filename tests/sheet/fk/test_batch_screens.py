"""The vectorised screens of the batch result (fk._batch_result, fk.results) against the
plain numpy expressions they replace."""

import numpy as np
import pytest

from taut.sheet.fk._batch_result import _close_states
from taut.sheet.fk.results import _has_kind


@pytest.mark.parametrize("K", [0, 1, 2, 3, 7])
def test_has_kind_is_any_over_slots(K):
    rng = np.random.default_rng(K)
    kinds = rng.integers(-1, 4, size=(500, K)).astype(np.int8)
    for code in (-1, 0, 1, 3):
        expect = np.any(kinds == code, axis=1)
        got = _has_kind(kinds, code)
        assert got.dtype == bool and got.shape == (500,)
        np.testing.assert_array_equal(got, expect)


@pytest.mark.parametrize("K", [2, 3, 5])
def test_close_states_is_the_all_pairs_screen(K):
    rng = np.random.default_rng(10 + K)
    B, tol = 3000, 1e-6
    obj = rng.normal(size=(B, K, 3))
    # Some slots copied to within tol (all coordinates), some close in x only, some in
    # x and y only, exactly tol apart, and NaN padding.
    obj[::7, 1] = obj[::7, 0] + rng.uniform(-tol, tol, size=(len(obj[::7]), 3))
    obj[1::11, K - 1, 0] = obj[1::11, 0, 0]
    obj[2::13, K - 1, :2] = obj[2::13, 0, :2]
    obj[3::17, 1] = obj[3::17, 0] + tol
    obj[4::5, K - 1] = np.nan
    obj[5::19, 1:] = np.nan
    with np.errstate(invalid="ignore"):
        iu, ju = np.triu_indices(K, 1)
        expect = np.flatnonzero(np.any(np.abs(obj[:, iu] - obj[:, ju]).max(axis=2) <= tol,
                                       axis=1))
    got = _close_states(obj, tol)
    assert len(expect) > B // 10
    np.testing.assert_array_equal(got, expect)
