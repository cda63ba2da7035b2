import json
from pathlib import Path

import numpy as np
import pytest

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
