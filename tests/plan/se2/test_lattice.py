"""The multi-formation lattice search: A* against SciPy's Dijkstra on the same lattice,
formation changes, determinism, and the plans it returns."""

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from taut.plan import Obstacle, Scenario, World, formation_library, generate_scenario, plan
from taut.plan.se2 import _lattice, _rigid
from taut.plan import _tol
from taut.plan._kernels.lattice import OFFSETS
from taut.plan._kernels.clearance import morph_clear
from taut.plan.se2._space import PoseChecker

from ..test_plan import corridor_team


@pytest.fixture(scope="module")
def small():
    """A corridor too narrow to pass the low post beside it (the team must cross it, with
    the object high), then a 1 m passage only the compact formation fits: one change."""
    world = World([[0, -0.7], [2.3, -0.7], [2.3, -0.5], [3.8, -0.5], [3.8, 0.5],
                   [2.3, 0.5], [2.3, 0.7], [0, 0.7]],
                  (Obstacle("post", 0.1, center=[1.3, 0.05], radius=0.08),))
    sc = Scenario(world, corridor_team(), [0.6, 0.0], [3.1, -0.1])
    compact, others, _ = formation_library(sc, sheet_margin=0.01)
    forms = [compact, others[0]]
    return sc, forms, [PoseChecker(sc, f, allow_crossing=True) for f in forms]


def _oracle(sc, forms, checkers, grid):
    """The fastest lattice path by SciPy's Dijkstra on an explicitly built graph (edges
    by the same rules as the kernel, searched by another algorithm)."""
    C, nk, dpsi = len(grid.cells), grid.nk, grid.dpsi
    L = len(forms)
    team = sc.team
    pose = lambda c, k: np.array([*grid.cells[c], -np.pi + k * dpsi])  # noqa: E731
    clear = np.array([[ch.clearance(np.array([pose(c, k) for k in range(nk)]))
                       for c in range(C)] for ch in checkers])          # (L, C, nk)
    ok = clear >= _tol.STATE_CLEARANCE
    node = lambda l, c, k: (l * C + c) * nk + k                      # noqa: E731
    total = L * C * nk + 1
    goal = total - 1
    rows, cols, w = [], [], []
    cidx, kidx = np.meshgrid(np.arange(C), np.arange(nk), indexing="ij")
    for l, ch in enumerate(checkers):
        for m in range(9):
            c2 = cidx if m == 8 else grid.nbr[cidx, m]
            for dk in (-1, 0, 1):
                if m == 8 and dk == 0:
                    continue
                k2 = (kidx + dk) % nk
                both = (c2 >= 0) & ok[l, cidx, kidx] & ok[l, np.maximum(c2, 0), k2]
                for c, k, cc in zip(cidx[both], kidx[both], c2[both]):
                    move = float(np.linalg.norm(grid.cells[cc] - grid.cells[c]))
                    a, b = pose(c, k), pose(cc, k)
                    b[2] = a[2] + dk * dpsi
                    disp = move + ch.radius * dpsi * abs(dk)
                    if (clear[l, c, k] + clear[l, cc, (k + dk) % nk] - disp
                            < 2 * _tol.MOTION_MARGIN and not ch.motion_valid(a, b)):
                        continue
                    rows.append(node(l, c, k))
                    cols.append(node(l, cc, (k + dk) % nk))
                    w.append(max(move / team.speed, dpsi * abs(dk) / team.rotation_speed))
    cost, obst, _ = _lattice._changes(sc, forms, checkers)
    for a in range(L):
        for b in range(L):
            if a == b or not np.isfinite(cost[a, b]):
                continue
            for c in range(C):
                for k in range(nk):
                    if not (ok[a, c, k] and ok[b, c, k]):
                        continue
                    q = pose(c, k)
                    A, B = forms[a].placed(q[:2], q[2]), forms[b].placed(q[:2], q[2])
                    if morph_clear(A, B, q[0], q[1], max(checkers[a].radius, checkers[b].radius),
                                   checkers[a]._walls, obst[a, b], checkers[a]._verts,
                                   checkers[a].clearance_rule, _tol.MOTION_MARGIN,
                                   _tol.MIN_ADVANCE) > 0:
                        rows.append(node(a, c, k))
                        cols.append(node(b, c, k))
                        w.append(cost[a, b])
    ids, gcost = _rigid.goal_links(grid, checkers, sc.goal, sc.team.speed,
                                   sc.team.rotation_speed)
    rows += list(ids)
    cols += [goal] * len(ids)
    w += list(gcost)
    g = csr_matrix((w, (rows, cols)), shape=(total, total))
    starts = [node(l, grid.start_cell, k) for l in range(L) for k in range(nk)
              if ok[l, grid.start_cell, k]]
    return float(dijkstra(g, indices=starts, min_only=True)[goal])


def _grid(sc, spacing, radius, layers):
    """The lattice of the shared core (:func:`taut.plan.se2._rigid.lattice_grid`)."""
    return _rigid.lattice_grid(sc.world.geometry, sc.world.free_space, sc.start, spacing,
                               radius, layers)


def test_astar_finds_the_fastest_lattice_path(small, monkeypatch):
    sc, forms, checkers = small
    res = _lattice.lattice_search(sc, forms, checkers, spacing=0.1, expansions=10**7,
                                  rng=np.random.default_rng(0))
    grid = _grid(sc, 0.1, max(c.radius for c in checkers), len(forms))
    best = _oracle(sc, forms, checkers, grid)
    assert np.isfinite(best) and res.pieces is not None
    assert res.cost == pytest.approx(best, rel=1e-12)
    assert not res.exhausted


def test_lattice_plan_changes_formation_and_is_verified(small):
    sc, forms, checkers = small
    res = _lattice.lattice_search(sc, forms, checkers, spacing=0.05, expansions=10**7,
                                  rng=np.random.default_rng(0))
    assert res.pieces is not None
    again = _lattice.lattice_search(sc, forms, checkers, spacing=0.05, expansions=10**7,
                                    rng=np.random.default_rng(0))
    for p, q in zip(res.pieces, again.pieces):                 # deterministic
        assert np.array_equal(p.waypoints, q.waypoints) and p.to is q.to
    r = plan(sc, search="lattice")
    assert r.success and r.search == "lattice" and r.crossed == ("post",)
    assert [f.kind for f in r.formations] == ["crossing", "compact"]
    assert [p.to is not None for p in res.pieces].count(True) == 1
    # Every rigid piece keeps the rules continuously (the checker's motion proof).
    for p in res.pieces:
        c = checkers[forms.index(p.formation)]
        for a, b in zip(p.waypoints[:-1], p.waypoints[1:]):
            assert c.motion_valid(a, b)


def test_budget_and_coarsening_are_reported(small, monkeypatch):
    sc, forms, checkers = small
    res = _lattice.lattice_search(sc, forms, checkers, spacing=0.05, expansions=10,
                                  rng=np.random.default_rng(0))
    assert res.pieces is None and res.exhausted and res.expanded == 11
    monkeypatch.setattr(_rigid, "MAX_NODES", 20_000)
    res = _lattice.lattice_search(sc, forms, checkers, spacing=0.01, expansions=10**7,
                                  rng=np.random.default_rng(0))
    assert res.spacing > 0.01
    grid = _grid(sc, 0.01, max(c.radius for c in checkers), len(forms))
    assert len(grid.cells) * grid.nk * len(forms) <= 20_000


def test_neighbour_table_matches_offsets(small):
    sc, forms, checkers = small
    grid = _grid(sc, 0.1, 0.5, 1)
    for c in range(len(grid.cells)):
        for m, (di, dj) in enumerate(OFFSETS):
            n = grid.nbr[c, m]
            want = grid.cells[c] + grid.spacing * np.array([di, dj])
            hit = np.flatnonzero(np.linalg.norm(grid.cells - want, axis=1) < 1e-9)
            assert (n == hit[0]) if len(hit) else (n == -1)
    assert np.allclose(grid.cells[grid.start_cell], sc.start)


# ~5 s of CPU: the slow target (CI runs it); test_lattice_plan_changes_formation_and_is_verified
# keeps a lattice formation change in the fast suite.
@pytest.mark.slow
def test_two_formation_changes_in_an_l_corridor():
    """Suite scenario 2034 (7 robots, L-shaped corridor): the lattice crosses the first
    low obstacle, changes formation to cross one taller, and changes again in the
    corner: the crossing search's own plan, before the planner compares it with the
    bypass search's (which gets through in one squeezed formation and is faster here)."""
    from taut.plan import planner
    from taut.plan._options import plan_options

    sc = generate_scenario(2034, 7)
    opts = plan_options(search="lattice")
    r = planner._se2(sc, allow_crossing=True, sheet_margin=opts.sheet_margin,
                     budget=opts.budget, planner="crossing",
                     library=planner.library(sc, opts.sheet_margin), search="lattice")
    assert r.success, r.message
    assert plan(sc, search="lattice").duration <= r.duration
    assert len(r.formations) >= 2
    rigid = np.abs(np.diff(np.linalg.norm(r.robots[:, 0] - r.robots[:, 1], axis=1))) < 1e-9
    changes = np.flatnonzero(np.diff(np.concatenate([[1], (~rigid).astype(int)])) == 1)
    assert len(changes) >= 2


def test_change_rules_block_obstacles_the_lowest_object_does_not_clear(small):
    sc, forms, checkers = small
    cost, obst, refused = _lattice._changes(sc, forms, checkers)
    assert not refused and np.all(np.isfinite(cost[~np.eye(2, dtype=bool)]))
    low = min(f.object_height for f in forms)
    post = sc.world.obstacle("post")
    # The compact formation's object (0.05 m) cannot clear the 0.1 m post: blocked during
    # either change; flags are exactly 0 or 1.
    assert low - sc.team.height_safety < post.height
    assert obst[0, 1][0, 3] == 1.0 and obst[1, 0][0, 3] == 1.0
    assert set(np.unique(obst[..., 3])) <= {0.0, 1.0}
    # Without crossing every obstacle is blocked.
    bypass = [PoseChecker(sc, f, allow_crossing=False) for f in forms]
    _, obst_b, _ = _lattice._changes(sc, forms, bypass)
    assert np.all(obst_b[0, 1][:, 3] == 1.0)
