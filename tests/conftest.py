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
settings.register_profile("full", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci" if os.environ.get("CI") else "dev")

# Example counts: a test's own `max_examples` is what CI draws ("ci") and what
# `pytest --hypothesis-profile=full` draws; a developer's run ("dev", so `make test` on a
# workstation) draws a quarter of it, at least DEV_MIN_EXAMPLES, to keep the fast suite
# quick. The draws are random there, so over many runs the full space is still searched.
EXAMPLE_SHARE = {"dev": 0.25}
DEV_MIN_EXAMPLES = 10


def pytest_collection_modifyitems(items):
    share = EXAMPLE_SHARE.get(settings.get_current_profile_name(), 1.0)
    if share == 1.0:
        return
    done = set()
    for item in items:
        test = getattr(item, "obj", None)
        test = getattr(test, "__func__", test)        # a method: its function
        if not getattr(test, "is_hypothesis_test", False) or id(test) in done:
            continue
        done.add(id(test))  # parametrized cases share one function: scale it once
        # hypothesis reads this attribute when the test runs (what @settings sets)
        own = test._hypothesis_internal_use_settings
        count = max(min(own.max_examples, DEV_MIN_EXAMPLES), round(own.max_examples * share))
        test._hypothesis_internal_use_settings = settings(own, max_examples=count)

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
