"""Inputs that once made the fast method disagree with Algorithm 1."""

import json
from pathlib import Path

import numpy as np
import pytest

from taut.sheet import Sheet, forward_kinematics
from taut.sheet import fk as fk_module

DATA = Path(__file__).parents[1] / "data"


@pytest.mark.parametrize("small_team", [fk_module.SMALL_TEAM, 3])
def test_nearly_coplanar_upper_facets(monkeypatch, small_team):
    """Lifted points whose hull has nearly coplanar neighbouring facets (equations 1e-6
    apart): the closed form from facet normals must not lose the 2-face {2,3,6} (1-based).
    ``small_team = 3`` forces the convex-hull path for this 7-robot team."""
    monkeypatch.setattr(fk_module, "SMALL_TEAM", small_team)
    case = json.loads((DATA / "fk_coplanar_facets_case.json").read_text())
    sheet, formation = Sheet(case["sheet"]), np.array(case["formation"])
    fast = forward_kinematics(sheet, formation, case["hold_height"])
    exhaustive = forward_kinematics(sheet, formation, case["hold_height"], method="exhaustive")
    assert [e.taut for e in fast.equilibria] == [e.taut for e in exhaustive.equilibria]
    assert (1, 2, 5) in [e.taut for e in fast.equilibria]


def test_state_at_a_taut_set_change_stays_an_equilibrium():
    """Just past a taut-set change one cable is taut only within the taut tolerance and
    carries a weight of -1e-9: the state is still the stable rest state (all methods)."""
    case = json.loads((DATA / "fk_transition_case.json").read_text())
    sheet, formation = Sheet(case["sheet"]), np.array(case["formation"])
    for method in ("fast", "subsets", "exhaustive"):
        r = forward_kinematics(sheet, formation, case["hold_height"], method=method)
        assert [(e.taut, e.status) for e in r.equilibria] == [((1, 2, 5, 6), "stable")]
