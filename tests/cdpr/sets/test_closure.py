"""Wrench closure (exact test per pose) and the fully constrained FASTKIT preset."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import linprog

from taut.cdpr import (cable_state, grid_points, wrench_closure, wrench_feasible,
                       wrench_feasible_workspace)
from taut.io.cdpr_model import load_cdpr_model


@pytest.fixture(scope="module")
def fc():
    return load_cdpr_model("fastkit_fc")


@pytest.fixture(scope="module")
def grid(fc):
    return grid_points(fc.desired_workspace, (21, 1, 11))


def _spans_by_sampling(W, g, n_dirs=40):
    """Independent check: LP feasibility of W t = w, t >= 0, for the +-axes and random
    directions w (necessary for closure), and Gordan's alternative: no y != 0 with
    y^T W >= 0 (searched by LP over a box, y^T W >= 0, max sum of y^T W)."""
    n, m = W.shape
    dirs = np.vstack([np.eye(n), -np.eye(n), g.normal(size=(n_dirs, n))])
    reach = all(linprog(np.zeros(m), A_eq=W, b_eq=w, bounds=[(0, None)] * m,
                        method="highs").status == 0 for w in dirs)
    sep = linprog(-W.sum(axis=1), A_ub=-W.T, b_ub=np.zeros(m), bounds=[(-1, 1)] * n,
                  method="highs")
    separated = sep.status == 0 and -sep.fun > 1e-7
    return reach, separated


def test_closure_matches_independent_checks(fc, grid):
    pts, _ = grid
    wc = wrench_closure(fc, pts)
    assert 0 < wc.sum() < len(pts)
    g = np.random.default_rng(3)
    st = cable_state(fc, pts)
    for k in g.choice(len(pts), 25, replace=False):
        reach, separated = _spans_by_sampling(st.W[k], g)
        if wc[k]:
            assert reach and not separated
        else:
            assert separated or not reach


def test_suspended_robot_has_no_closure(fastkit, grid):
    pts, _ = grid
    assert not wrench_closure(fastkit, pts).any()
    # yet it holds its weight over much of the slice: it relies on gravity
    assert wrench_feasible(fastkit, pts, tipping=False).mean() > 0.4


def test_closure_contains_feasible_without_gravity(fc, grid):
    """With t_min > 0 and no gravity, balancing the zero wrench within the limits is a
    strictly positive self-stress of a full-rank W: wrench-feasible => closure."""
    pts, _ = grid
    free = replace(fc, gravity=(0.0, 0.0, 0.0))
    feas = wrench_feasible(free, pts, tipping=False)
    wc = wrench_closure(fc, pts)
    assert feas.any() and not np.any(feas & ~wc)


def test_fully_constrained_preset_differs_only_in_the_low_pulleys(fastkit, fc):
    assert fc.m == fastkit.m == 8 and fc.dof == 6
    low = fc.exits_world[:, 2] < 1.0
    assert low.sum() == 4 and np.allclose(fc.exits_world[low, 2], 0.30)
    np.testing.assert_array_equal(fc.exits_world[~low], fastkit.exits_world[~low])
    np.testing.assert_array_equal(fc.attach_local, fastkit.attach_local)
    assert fc.total_mass == fastkit.total_mass and np.all(fc.t_max == 45.0)
    pts, shape = grid_points(fc.desired_workspace, (11, 1, 6))
    ws = wrench_feasible_workspace(fc, pts, shape=shape)
    assert ws.coverage_tipping is not None and ws.coverage_tipping <= ws.coverage
