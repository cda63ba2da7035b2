"""MuJoCo cross-checks of taut's sheet forward kinematics (needs the physics extra).

Tolerances (scenario units, documented in examples/physics/README.md): heights within
5 mm (ball radius accounted for); lateral position within 2 % of the sheet's width
(released, a ball of radius 0.05 spacings drifts by a few mm on Example 1; lateral
position is ill-conditioned in flat valleys).
"""

from pathlib import Path

import numpy as np
import pytest

from taut.errors import InvalidInputError
from taut.io import load_sheet_scenario
from taut.sheet import Sheet, forward_kinematics

mujoco = pytest.importorskip("mujoco")

from taut.physics import check_equilibria, settle  # noqa: E402

EXAMPLES = Path(__file__).parents[2] / "examples" / "sheet"
HEIGHT_TOL = 5.0          # mm
LATERAL_FRACTION = 0.02   # of the sheet's width


def _assert_agrees(sheet, R, z, *, heights_mm=True):
    result = check_equilibria(sheet, R, z)
    width = float(np.max(sheet.side_lengths()))
    fk = forward_kinematics(sheet, R, z)
    assert [s.taut for s in result.states] == [e.taut for e in fk.equilibria]
    scale = 1.0 if heights_mm else width / 1000.0
    for s in result.states:
        if s.status == "stable":
            assert s.held, s
            for diff in (s.tied_difference, s.difference):
                assert abs(diff[2]) <= HEIGHT_TOL * scale, s
                assert np.hypot(*diff[:2]) <= LATERAL_FRACTION * width, s
        elif s.status == "not_equilibrium":
            assert not s.held, s
    assert result.success and result.status == "ok"
    return result


def test_triangle_team():
    sheet = Sheet.regular(3, 600.0)
    R = 0.75 * sheet.vertices + [30.0, -20.0]
    result = _assert_agrees(sheet, R, 700.0)
    assert len(result.states) == 1


@pytest.mark.slow
def test_free_drop_finds_the_triangle_state():
    # A triangle has one rest state; a ball dropped over the robots' centroid finds it:
    # the height closely, the place within 5 % of the width (a dropped ball keeps the
    # patch of coarse mesh it lands on, and the valley is flat; measured 32 mm here).
    sheet = Sheet.regular(3, 600.0)
    R = 0.75 * sheet.vertices + [30.0, -20.0]
    eq = forward_kinematics(sheet, R, 700.0).equilibria[0]
    r = settle(sheet, R, 700.0, trace=True)
    assert r.success and r.converged
    assert abs(r.position[2] - eq.object[2]) <= HEIGHT_TOL
    assert np.hypot(*(r.position[:2] - eq.object[:2])) <= 0.05 * 1039.2
    assert r.trace is not None and r.trace.shape[1] == 4
    assert np.all(np.diff(r.trace[:, 0]) > 0)


@pytest.mark.slow
def test_fk_paper_example1():
    sc = load_sheet_scenario(EXAMPLES / "example1.yaml")
    result = _assert_agrees(sc.sheet, sc.formation, sc.hold_height)
    status = {s.taut: s.status for s in result.states}
    assert status == {(0, 1, 2): "stable", (0, 2, 3): "stable",
                      (0, 1, 2, 3): "not_equilibrium"}


@pytest.mark.slow
def test_fk_paper_example2_eight_robots():
    sc = load_sheet_scenario(EXAMPLES / "example2_r2_r4_353mm.yaml")
    result = _assert_agrees(sc.sheet, sc.formation, sc.hold_height)
    held = [s.taut for s in result.states if s.held]
    assert held == [(3, 4, 7)]                       # only {4,5,8} (1-based) is held


def test_bad_options_are_typed_errors():
    sheet = Sheet.regular(3, 600.0)
    R = 0.75 * sheet.vertices
    with pytest.raises(InvalidInputError, match="mesh"):
        check_equilibria(sheet, R, 700.0, mesh=2)
    with pytest.raises(InvalidInputError, match="ball"):
        settle(sheet, R, 700.0, ball=-1.0)
    with pytest.raises(InvalidInputError, match="start"):
        settle(sheet, R, 700.0, start=[0.0, 0.0])


@pytest.mark.slow
def test_units_and_placement_do_not_change_the_answer():
    # The same team in metres, moved by (3, -2) m: the same verdicts, and differences that
    # are the millimetre ones scaled by 1/1000 (the simulation is scaled to the sheet).
    sc = load_sheet_scenario(EXAMPLES / "example1.yaml")
    mm = check_equilibria(sc.sheet, sc.formation, sc.hold_height)
    shift = np.array([3.0, -2.0])
    m = check_equilibria(Sheet(sc.sheet.vertices / 1000 + shift), sc.formation / 1000 + shift,
                         sc.hold_height / 1000)
    assert [s.held for s in m.states] == [s.held for s in mm.states]
    for a, b in zip(mm.states, m.states):
        np.testing.assert_allclose(b.tied_difference * 1000, a.tied_difference, atol=0.5)
        assert abs(b.sliding - a.sliding) <= 0.01
