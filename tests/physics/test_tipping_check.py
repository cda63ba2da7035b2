"""MuJoCo cross-check of FASTKIT's tipping moments (eqs. 21-23) on the fastkit preset."""

import numpy as np
import pytest

from taut.cdpr import distribute_tensions
from taut.errors import InvalidInputError
from taut.io.cdpr_model import load_cdpr_model

mujoco = pytest.importorskip("mujoco")

from taut.physics import replay_tipping, replay_tipping_grid  # noqa: E402


@pytest.fixture(scope="module")
def robot():
    return load_cdpr_model("fastkit")


def _tensions(robot, pose):
    res = distribute_tensions(robot, pose, "lp_min_sum", tipping=False)
    assert res.success
    return res.tensions


def test_clearly_negative_margin_tips(robot):
    pose = [0.0, 0.0, 1.4, 0.0, 0.0, 0.0]
    r = replay_tipping(robot, pose, _tensions(robot, pose))
    assert r.margin < -100.0                    # taut: a base tips (N m)
    assert "tips" in r.verdicts and not r.physics_stays
    assert r.success and r.status == "ok"


def test_clearly_positive_margin_stays(robot):
    pose = [-2.0, 0.0, 0.2, 0.0, 0.0, 0.0]
    r = replay_tipping(robot, pose, _tensions(robot, pose))
    assert r.margin > 100.0
    assert r.verdicts == ("stays", "stays")
    assert np.all(r.tilt < 0.5) and np.all(r.slip < 0.005)
    assert r.success


def test_no_friction_means_sliding(robot):
    # FASTKIT's static model assumes the bases do not slide; on a slippery floor the
    # horizontal cable pull moves a base that taut says does not tip.
    pose = [-2.0, 0.0, 0.2, 0.0, 0.0, 0.0]
    r = replay_tipping(robot, pose, _tensions(robot, pose), friction=0.01)
    assert r.taut_stays and "slides" in r.verdicts and not r.success


@pytest.mark.slow
def test_grid_agrees_away_from_the_boundary(robot):
    poses = [[x, 0.0, z, 0, 0, 0] for x in (-2.0, -1.0, 0.0, 1.0, 2.0) for z in (0.2, 1.4)]
    g = replay_tipping_grid(robot, poses, method="lp_min_sum", tipping=False)
    clear = g.feasible & (np.abs(g.margin) > 20.0)
    assert clear.sum() >= 5
    assert np.all(g.success[clear])


def test_bad_tensions(robot):
    with pytest.raises(InvalidInputError, match="tensions"):
        replay_tipping(robot, [0.0, 0.0, 1.0], np.full(7, 10.0))
    with pytest.raises(InvalidInputError, match="tensions"):
        replay_tipping(robot, [0.0, 0.0, 1.0], np.full(8, -1.0))
