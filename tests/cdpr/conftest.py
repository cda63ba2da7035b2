"""Fixtures for the cable-robot tests: the two presets and hand-checkable robots."""

import pytest

from cdpr_helpers import point_mass_robot
from taut.io.cdpr_model import load_cdpr_model


@pytest.fixture(scope="session")
def fastkit():
    return load_cdpr_model("fastkit")


@pytest.fixture(scope="session")
def ipanema():
    return load_cdpr_model("ipanema")


@pytest.fixture
def point_mass():
    return point_mass_robot()
