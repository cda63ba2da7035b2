"""Fixtures shared by the planning tests."""

from pathlib import Path

import pytest

from taut.io import load_plan_scenario
from taut.plan import plan

EXAMPLES = Path(__file__).parents[2] / "examples" / "plan"


@pytest.fixture(scope="session")
def paper_corridor_plan():
    """The planning paper's corridor and the default planner's plan of it."""
    sc = load_plan_scenario(EXAMPLES / "paper_corridor.yaml")
    return sc, plan(sc)
