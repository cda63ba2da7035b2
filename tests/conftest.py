import json
import os
from pathlib import Path

# The suite runs the compiled kernels, compiling what numba's cache lacks (`make test`
# warms the cache first), and compares them with the numpy engines; the default "auto"
# would pick numpy on a cold cache and skip those comparisons (src/taut/_jit.py).
os.environ.setdefault("TAUT_NUMBA", "always")

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# CI (CI=true) draws the same hypothesis examples on every run, so a landing is decided by
# the code, not by the draw; elsewhere examples are random (more teams tried over time).
# No deadlines: the test machine is shared and timing is not what these tests check.
settings.register_profile("ci", derandomize=True, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci" if os.environ.get("CI") else "dev")

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).parent.parent


@pytest.fixture(scope="session")
def reference():
    """Outputs of the FK paper authors' code on the paper's examples (mm)."""
    return json.loads((DATA / "vvcm_reference_outputs.json").read_text())["examples"]


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def examples_dir():
    return ROOT / "examples"
