import numpy as np
import pytest

pytest.importorskip("pyarrow")

from taut.sweep import sweep_from_mapping  # noqa: E402

EXAMPLE2 = "examples/sheet/example2_r2_r4_353mm.yaml"


@pytest.fixture
def fk_spec(examples_dir):
    def make(**parameters):
        return sweep_from_mapping({"task": "fk_stability_map", "base": EXAMPLE2,
                                   "chunk_size": 16, "parameters": parameters},
                                  examples_dir.parent)
    return make


@pytest.fixture
def same_rows():
    return _same_rows


def _same_rows(a, b):
    assert list(a) == list(b)
    for k in a:
        if a[k].dtype.kind == "f":
            np.testing.assert_array_equal(a[k], b[k])
        else:
            assert list(a[k]) == list(b[k]), k
