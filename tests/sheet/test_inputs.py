"""Bad input raises typed errors naming the field; good input in any orientation works."""

import numpy as np
import pytest

from taut.errors import (InfeasibleFormationError, InvalidInputError, InvalidSheetError,
                         TautError)
from taut.sheet import Sheet, forward_kinematics, forward_kinematics_batch
from taut.sheet import SheetTeam

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
    a = forward_kinematics(SheetTeam(Sheet(SQUARE), 1.0), INNER)
    b = forward_kinematics(SheetTeam(cw, 1.0), INNER[::-1])
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
    args = dict(sheet=Sheet(SQUARE), formation=INNER, hold_height=1.0, mass=None)
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as info:
        team = SheetTeam(args.pop("sheet"), args.pop("hold_height"), mass=args.pop("mass"))
        forward_kinematics(team, **args)
    assert info.value.field == field


def test_analyses_take_a_sheet_team():
    with pytest.raises(InvalidInputError) as info:
        forward_kinematics(Sheet(SQUARE), INNER)             # type: ignore[arg-type]
    assert info.value.field == "team" and "SheetTeam" in info.value.problem


def test_infeasible_formation_names_the_pair():
    wide = INNER.copy()
    wide[2] = [1.5, 1.5]                      # robots 2-3 and 3-4 too far apart
    with pytest.raises(InfeasibleFormationError) as info:
        forward_kinematics(SheetTeam(Sheet(SQUARE), 1.0), wide)
    assert info.value.pair in {(1, 2), (2, 3), (0, 2)}
    assert "sheet would tear" in str(info.value)
    assert isinstance(info.value, TautError)


def test_batch_flags_the_infeasible_formation_and_answers_the_others():
    forms = np.stack([INNER, INNER, INNER * 2.0])
    res = forward_kinematics_batch(SheetTeam(Sheet(SQUARE), 1.0), forms)
    assert res.feasible.tolist() == [True, True, False]
    assert res.success.tolist() == [True, True, False]
    assert res.status.tolist() == ["ok", "ok", "infeasible"]
    assert res.count[2] == 0 and res.count[:2].tolist() == [1, 1]
    assert "formation 2: robots" in res.message and "sheet would tear" in res.message
    one = forward_kinematics(SheetTeam(Sheet(SQUARE), 1.0), INNER)
    assert res.result(0).lowest.taut == one.lowest.taut
    with pytest.raises(InfeasibleFormationError):          # as the single form raises
        res.result(2)


def test_exhaustive_refuses_huge_teams():
    sheet = Sheet.regular(30, 1.0)
    t = 2 * np.pi * np.arange(30) / 30
    with pytest.raises(InvalidInputError) as info:
        forward_kinematics(SheetTeam(sheet, 1.0), 0.5 * np.column_stack([np.cos(t), np.sin(t)]),
                           method="exhaustive")
    assert info.value.field == "method"


def test_object_on_the_ground_gives_no_solution():
    """z_o must be positive (FK paper eq. 15): a low hold height leaves no rest state."""
    r = forward_kinematics(SheetTeam(Sheet(SQUARE), 0.05), INNER)
    assert r.equilibria == () and r.lowest is None


def test_robots_at_sheet_limit_are_feasible():
    """Pairs exactly as far apart as their vertices (a taut sheet edge) are allowed."""
    r = forward_kinematics(SheetTeam(Sheet(SQUARE), 1.0), np.array(SQUARE, float) * 1.0)
    assert isinstance(r.equilibria, tuple)
