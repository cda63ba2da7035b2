"""The bases' own inertia in tipping and sliding (issue 30: a base that drives feels its
d'Alembert force ``-m_b a`` at its centre of mass), checked against a moment balance about
the tipping edge computed by hand and against the contact-force balance of the friction
pyramid."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from taut.cdpr import (cable_state, sliding_rows, tipping_moments, with_base_acceleration,
                       with_friction)
from taut.errors import InvalidInputError

G = 9.81


def _back_edge(robot):
    """Index of the active base's back wheel edge (base frame x = -0.45 m; active base at
    world x = -3, yaw 0, so world x = -3.45)."""
    on = (robot.edge_base == 0) & np.isclose(robot.edge_points[:, 0], -3.45)
    on &= np.isclose(robot.edge_dirs[:, 0], 0.0)
    (j,) = np.nonzero(on)[0]
    return int(j)


@settings(max_examples=25, deadline=None)
@given(a=st.floats(0.0, 6.0))
def test_hand_computed_margin_about_the_back_edge(fastkit, a):
    # Active base: 45 kg, centre of mass 0.4 m ahead of the back wheels, 0.6 m up. Driving
    # forward at a, the d'Alembert force 45 a N points back at 0.6 m: the restoring moment
    # of the weight about the back edge, 45 g 0.4, loses 45 a 0.6 (N m).
    robot = with_base_acceleration(fastkit, [a, 0.0, 0.0])
    j = _back_edge(robot)
    assert -robot.edge_weight_moment[j] == pytest.approx(45.0 * G * 0.4 - 45.0 * a * 0.6,
                                                         rel=1e-12, abs=1e-9)


@settings(max_examples=25, deadline=None)
@given(ax=st.floats(-3.0, 3.0), ay=st.floats(-3.0, 3.0))
def test_every_edge_loses_m_h_a_along_its_inward_normal(fastkit, ax, ay):
    # The horizontal force -m a at height h about a horizontal edge with inward normal n:
    # the edge moment grows by m h (a . n), so the margin falls as the base accelerates
    # away from the edge and grows as it accelerates towards it.
    rest, moving = fastkit, with_base_acceleration(fastkit, [ax, ay, 0.0])
    u = rest.edge_dirs[:, :2]
    inward = np.column_stack([-u[:, 1], u[:, 0]])           # left of a CCW edge
    h = np.array([rest.bases[k].com[2] for k in rest.edge_base])
    m = np.array([rest.bases[k].mass for k in rest.edge_base])
    expected = rest.edge_weight_moment + m * h * (inward @ np.array([ax, ay]))
    assert np.allclose(moving.edge_weight_moment, expected, atol=1e-9)
    # the same shift in the tipping moments of the statics, tensions held
    pose, t = [-1.0, 0.0, 0.8], fastkit.t_min + 3.0
    shift = (tipping_moments(moving, pose, t).moments
             - tipping_moments(rest, pose, t).moments)
    assert np.allclose(shift, expected - rest.edge_weight_moment, atol=1e-9)


def test_margin_falls_with_acceleration_away_from_the_edge(fastkit):
    j = _back_edge(fastkit)
    margins = [-with_base_acceleration(fastkit, [a, 0, 0]).edge_weight_moment[j]
               for a in (0.0, 0.25, 1.0, 4.0)]
    assert np.all(np.diff(margins) < 0)
    # past g 0.4 / 0.6 = 6.54 m/s^2 the base tips over backwards with no cable at all
    assert -with_base_acceleration(fastkit, [6.6, 0, 0]).edge_weight_moment[j] < 0


@settings(max_examples=25, deadline=None)
@given(ax=st.floats(-3.0, 3.0), ay=st.floats(-3.0, 3.0))
def test_sliding_needs_the_force_that_accelerates_the_base(fastkit, ax, ay):
    # The ground pushes the base with m a on top of balancing the cables: each pyramid face
    # d_j . f <= mu N loses m (d_j . a) of its right-hand side.
    rest = with_friction(fastkit, 0.5)
    moving = with_base_acceleration(rest, [ax, ay, 0.0])
    unit = cable_state(rest, [0.0, 0.0, 1.0]).unit
    S0, s0, base = sliding_rows(rest, unit)
    S1, s1, _ = sliding_rows(moving, unit)
    phi = 2 * np.pi * np.arange(8) / 8
    d = np.tile(np.column_stack([np.cos(phi), np.sin(phi)]), (2, 1))
    assert np.array_equal(S0, S1)
    assert np.allclose(s1, s0 - 45.0 * (d @ np.array([ax, ay])), atol=1e-9)


def test_bad_acceleration_is_named(fastkit):
    with pytest.raises(InvalidInputError, match="acceleration"):
        with_base_acceleration(fastkit, [np.nan, 0, 0])
    with pytest.raises(InvalidInputError, match="acceleration"):
        with_base_acceleration(fastkit, [1.0, 0])


@pytest.mark.parametrize("a", [1e308, -1e7, 1.0000001e6])
def test_an_acceleration_past_the_accepted_range_is_named(fastkit, a):
    """Finite but past MAX_ACCELERATION (1e6 m/s^2): refused, not turned into NaN moments."""
    with pytest.raises(InvalidInputError, match=r"acceleration.*exceeds the accepted range"):
        with_base_acceleration(fastkit, [0.0, a, 0.0])
    assert np.isfinite(with_base_acceleration(fastkit, [0.0, 1e6, 0.0]).edge_weight_moment).all()
