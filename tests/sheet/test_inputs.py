"""Bad input raises typed errors naming the field; good input in any orientation works."""

import numpy as np
import pytest

from taut.errors import (InfeasibleFormationError, InvalidInputError, InvalidSheetError,
                         TautError)
from taut.sheet import Sheet, forward_kinematics, forward_kinematics_batch

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
INNER = np.array([[0.2, 0.2], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]])


@pytest.mark.parametrize("vertices,fragment", [
    ([[0, 0], [1, 0]], "at least 3"),
    ([[0, 0], [1, 0], [1, 0], [0, 1]], "repeats vertex"),
    ([[0, 0], [1, 0], [0.5, 0.2], [1, 1], [0, 1]], "not convex"),
    ([[0, 0], [1, 0], [2, 0]], "one line"),
    ([[0, 0], [np.nan, 0], [1, 1]], "NaN"),
    ([[1, 0], [-0.809, 0.588], [0.309, -0.951], [0.309, 0.951], [-0.809, -0.588]],
     "self-intersecting"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], "shape"),
    ("abc", "numeric"),
])
def test_bad_sheets(vertices, fragment):
    with pytest.raises(InvalidSheetError) as info:
        Sheet(vertices)
    assert fragment in str(info.value)
    assert info.value.field.startswith("sheet")


def test_clockwise_sheet_gives_same_answer():
    cw = Sheet(SQUARE[::-1])
    assert cw.orientation == "cw"
    a = forward_kinematics(Sheet(SQUARE), INNER, 1.0)
    b = forward_kinematics(cw, INNER[::-1], 1.0)
    assert len(a.equilibria) == len(b.equilibria) == 1
    np.testing.assert_allclose(a.equilibria[0].object, b.equilibria[0].object, atol=1e-12)


@pytest.mark.parametrize("kwargs,field", [
    (dict(formation=INNER[:3]), "formation"),
    (dict(formation=np.array([[0.2, np.inf]] + INNER[1:].tolist())), "formation"),
    (dict(formation=INNER.ravel()), "formation"),
    (dict(hold_height=0.0), "hold_height"),
    (dict(hold_height=-1.0), "hold_height"),
    (dict(hold_height=float("nan")), "hold_height"),
    (dict(mass=0.0), "mass"),
    (dict(method="magic"), "method"),
])
def test_bad_arguments(kwargs, field):
    args = dict(sheet=Sheet(SQUARE), formation=INNER, hold_height=1.0)
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as info:
        forward_kinematics(**args)
    assert info.value.field == field


def test_infeasible_formation_names_the_pair():
    wide = INNER.copy()
    wide[2] = [1.5, 1.5]                      # robots 2-3 and 3-4 too far apart
    with pytest.raises(InfeasibleFormationError) as info:
        forward_kinematics(Sheet(SQUARE), wide, 1.0)
    assert info.value.pair in {(1, 2), (2, 3), (0, 2)}
    assert "sheet would tear" in str(info.value)
    assert isinstance(info.value, TautError)


def test_batch_reports_infeasible_step():
    forms = np.stack([INNER, INNER, INNER * 2.0])
    with pytest.raises(InfeasibleFormationError) as info:
        forward_kinematics_batch(Sheet(SQUARE), forms, 1.0)
    assert info.value.step == 2


def test_exhaustive_refuses_huge_teams():
    sheet = Sheet.regular(30, 1.0)
    t = 2 * np.pi * np.arange(30) / 30
    with pytest.raises(InvalidInputError) as info:
        forward_kinematics(sheet, 0.5 * np.column_stack([np.cos(t), np.sin(t)]), 1.0,
                           method="exhaustive")
    assert info.value.field == "method"


def test_object_on_the_ground_gives_no_solution():
    """z_o must be positive (FK paper eq. 15): a low hold height leaves no rest state."""
    r = forward_kinematics(Sheet(SQUARE), INNER, 0.05)
    assert r.equilibria == () and r.lowest is None


def test_robots_at_sheet_limit_are_feasible():
    """Pairs exactly as far apart as their vertices (a taut sheet edge) are allowed."""
    r = forward_kinematics(Sheet(SQUARE), np.array(SQUARE, float) * 1.0, 1.0)
    assert isinstance(r.equilibria, tuple)
