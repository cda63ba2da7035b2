"""In-place formation changes: robots moving straight must not run into each other, and the
verifier sees a collision between samples."""

import numpy as np
from dataclasses import replace

from taut.plan import verify_motion
from taut.plan._se2_motion import change_profile
from taut.plan.library import _library

from .test_plan import corridor


def test_a_change_whose_robots_cross_is_refused_and_the_verifier_sees_it():
    sc = corridor([])
    compact, _, _ = _library(sc, 0.01)
    # The same formation with robots 1 and 2 exchanged: the straight motions cross.
    swapped = replace(compact, robots=compact.robots[[1, 0, 2]])
    prof = change_profile(sc, compact, swapped)
    assert prof.message is not None and "robots 1 and 2 would pass" in prof.message
    centre = np.array([2.0, 0.0])
    a = compact.placed(centre, np.asarray(0.0))
    b = swapped.placed(centre, np.asarray(0.0))
    robots = np.stack([a, b])                     # both samples keep the robots apart
    assert np.linalg.norm(a[0] - a[1]) > 0.3 and np.linalg.norm(b[0] - b[1]) > 0.3
    planned = np.full((2, 3), np.nan)
    r = verify_motion(sc, robots, planned)
    assert not r.success and "robots overlap" in r.message


def test_rigid_turns_keep_touching_footprints_apart():
    # Two robots exactly two radii apart, turning rigidly in coarse steps: the chord
    # between samples comes closer, the rigid motion does not.
    sc = corridor([])
    compact, _, _ = _library(sc, 0.01)
    R = compact.robots.copy()
    d = R[1] - R[0]
    R[1] = R[0] + d / np.linalg.norm(d) * 2 * sc.team.robot_radius
    f = replace(compact, robots=R)
    robots = np.stack([f.placed(np.array([3.0, 0.0]), np.asarray(a))
                       for a in np.linspace(0, 0.6, 4)])
    r = verify_motion(sc, robots, np.full((4, 3), np.nan))
    assert "overlap" not in r.message
