"""In-place formation changes: robots moving straight must not run into each other, and the
verifier sees a collision between samples."""

from dataclasses import replace

import numpy as np
import pytest

from taut.plan import plan_robustness, verify_motion
from taut.plan.se2._motion import change_profile
from taut.plan.formations.library import _library

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


def test_a_benign_change_tolerates_position_error():
    from taut.io import load_plan_scenario
    from taut.plan.checks.robustness import change_tolerates
    from .test_plan import EXAMPLES
    sc = load_plan_scenario(EXAMPLES / "paper_corridor.yaml")
    compact, others, _ = _library(sc, 0.01)
    assert change_tolerates(sc, compact, others[0]) is None
    assert change_tolerates(sc, others[0], compact) is None


@pytest.mark.slow
def test_fragile_changes_are_refused_and_the_plan_survives_its_monte_carlo():
    """Suite scenario 5027 (6 robots): the changes into and out of its squeezed formation
    move robots up to 0.75 m in place and drop the object under 5 mm of drifting robot
    error; the planner refuses them and its plan keeps the object in every trial."""
    from taut.plan import generate_scenario, plan
    from taut.plan.formations.library import _with_squeezed
    from taut.plan.checks.robustness import change_tolerates
    sc = generate_scenario(5027, 6)
    compact, others, _ = _library(sc, 0.01)
    forms = _with_squeezed(sc, [compact, *others], True, 0.01)
    squeezed = forms[-1]
    assert squeezed.kind == "squeezed"
    why = change_tolerates(sc, compact, squeezed)
    assert why is not None and "drops the object" in why
    r = plan(sc)
    assert r.success
    kinds = [f.kind for f in r.formations]
    assert not ("compact" in kinds and "squeezed" in kinds)
    rob = plan_robustness(r, 0.005, 10, seed=4)
    assert rob.failure_probability == 0.0


@pytest.mark.slow
def test_a_change_that_brings_the_object_below_the_height_safety_is_refused():
    """Suite scenario 5057: between its compact formation (object at the 0.04 m safety)
    and its squeezed one the object dips to 0.038 m; the verifier would refuse a plan with
    that change, so the planner must not use it (it found one that did, before)."""
    from taut.plan import generate_scenario, plan
    from taut.plan.formations.library import _with_squeezed
    sc = generate_scenario(5057, 6)
    compact, others, _ = _library(sc, 0.01)
    squeezed = _with_squeezed(sc, [compact, *others], True, 0.01)[-1]
    prof = change_profile(sc, compact, squeezed)
    assert prof.message is not None and "below the height safety" in prof.message
    assert prof.lowest < sc.team.height_safety
    r = plan(sc)
    assert r.success and r.verification.min_height_margin >= sc.team.height_safety - 1e-9
