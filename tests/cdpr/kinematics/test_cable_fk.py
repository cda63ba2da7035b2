"""Forward kinematics of the CDPR (cable lengths -> pose) against the inverse kinematics."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from taut.cdpr import cable_forward_kinematics, cable_state, rotation_matrices
from taut.cdpr.kinematics._bases import moved_exits
from taut.errors import InvalidInputError


def _random_poses(robot, n, seed, angle=0.2):
    g = np.random.default_rng(seed)
    box = robot.desired_workspace
    lo, hi = box[0].copy(), box[1].copy()
    lo[1], hi[1] = min(lo[1], -0.3), max(hi[1], 0.3)
    return np.column_stack([g.uniform(lo, hi, (n, 3)), g.uniform(-angle, angle, (n, 3))])


@pytest.mark.parametrize("preset", ["fastkit", "ipanema"])
def test_fk_inverts_ik_on_thousands_of_poses(preset, request):
    robot = request.getfixturevalue(preset)
    P = _random_poses(robot, 2000, seed=11)
    fk = cable_forward_kinematics(robot, cable_state(robot, P).lengths)
    assert fk.success.all(), fk.message
    assert np.abs(fk.poses[:, :3] - P[:, :3]).max() < 1e-9          # m
    R_fk, R_true = rotation_matrices(fk.poses[:, 3:]), rotation_matrices(P[:, 3:])
    assert np.abs(R_fk - R_true).max() < 1e-9


def test_fk_with_a_moved_mobile_base(fastkit):
    bp = np.array([b.pose for b in fastkit.bases])
    bp[0, 0] += 0.4                                   # active base 0.4 m towards the platform
    P = _random_poses(fastkit, 500, seed=3)
    P[:, 0] = np.clip(P[:, 0], -2.0, 2.4)
    ex = moved_exits(fastkit, bp[None])[0]
    att = P[:, None, :3] + np.einsum("bij,mj->bmi", rotation_matrices(P[:, 3:]),
                                     fastkit.attach_local)
    L = np.linalg.norm(ex[None] - att, axis=2)
    fk = cable_forward_kinematics(fastkit, L, base_poses=bp)
    assert fk.success.all()
    assert np.abs(fk.poses[:, :3] - P[:, :3]).max() < 1e-9
    # The same lengths with the base at its model pose are another pose (or none).
    other = cable_forward_kinematics(fastkit, L[:20])
    assert np.all(~other.success | (np.abs(other.poses[:, 0] - P[:20, 0]) > 1e-3))


@settings(max_examples=40, deadline=None)
@given(x=st.floats(-0.9, 0.9), y=st.floats(-0.6, 0.6), z=st.floats(0.9, 2.1),
       a=st.floats(-0.25, 0.25), b=st.floats(-0.25, 0.25), c=st.floats(-0.25, 0.25))
def test_fk_round_trip_property(ipanema, x, y, z, a, b, c):
    pose = np.array([x, y, z, a, b, c])
    fk = cable_forward_kinematics(ipanema, cable_state(ipanema, pose).lengths)
    assert fk.success
    assert np.abs(fk.poses - pose).max() < 1e-9


def test_inconsistent_lengths_are_reported_not_converged(ipanema):
    L = cable_state(ipanema, [0.0, 0.0, 1.5]).lengths.copy()
    L[0] *= 0.2                                  # no pose has these lengths
    fk = cable_forward_kinematics(ipanema, L, restarts=2)
    assert not fk.success and fk.status == "not_converged"
    assert fk.residual > 1e-3 and "residual" in fk.message


def test_all_solutions_counts_one_for_a_generic_fully_constrained_pose(ipanema):
    L = cable_state(ipanema, [0.2, -0.1, 1.4, 0.05, 0.0, 0.1]).lengths
    fk = cable_forward_kinematics(ipanema, L, all_solutions=True, restarts=4)
    assert fk.success and fk.n_solutions >= 1


@pytest.mark.parametrize("bad", [[1.0] * 7, [1.0] * 7 + [-1.0], [np.nan] * 8])
def test_bad_lengths_raise(ipanema, bad):
    with pytest.raises(InvalidInputError):
        cable_forward_kinematics(ipanema, bad)
