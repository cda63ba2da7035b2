"""Compiled A* over the multi-formation SE(2) lattice (:mod:`taut.plan.se2._lattice`).

A node is ``(layer, cell, k)``: formation ``layer`` with the object over lattice cell
``cell`` (a position in the free space) and heading ``-pi + k dpsi``; its id is
``(layer * C + cell) * nk + k``. Clearances (:func:`~taut.plan._kernels.clearance.robots_clearance`)
are computed when a node is first reached. A node is usable when its clearance is at least
``STATE_CLEARANCE``.

Moves from a node:

* to its 26 lattice neighbours in the same layer (headings wrap around). The straight
  SE(2) motion is valid when proved at once by the clearances ``c1``, ``c2`` of its ends,
  ``(c1 + c2 - D) / 2 >= margin`` (``D`` the largest robot displacement along it: the
  clearance is 1-Lipschitz in the robots' displacement), or else by conservative
  advancement (:func:`~taut.plan._kernels.clearance.motion_clear`). It costs
  ``max(distance / speed, turn / rotation speed)`` seconds;
* to the same pose in another layer, where the in-place change is allowed for the pair
  (the quasi-static model, decided once per pair by the caller) and valid for the
  geometry (:func:`~taut.plan._kernels.clearance.morph_clear` with the pair's obstacle rules);
  it costs the change's duration;
* to the goal, from the nodes the caller joined to it.

Rigid moves of a layer may be weighted (``weight`` >= 1: the caller's preference for some
formations). The heuristic, the straight-line distance to the goal over the speed, never
exceeds the cost left (every move takes at least its distance over the speed), so the
first time the goal is taken from the queue its path is the cheapest lattice path. The number of nodes
expanded is the search's deterministic budget.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from ..._jit import jit
from .clearance import morph_clear, motion_clear, robots_clearance

__all__ = ["lattice_astar", "OFFSETS"]

#: The eight position moves (di, dj) of a lattice cell, in the order of the caller's
#: neighbour table.
OFFSETS = np.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]])


@jit
def _place(local, x, y, psi, out):
    c, s = math.cos(psi), math.sin(psi)
    for i in range(local.shape[0]):
        out[i, 0] = c * local[i, 0] - s * local[i, 1] + x
        out[i, 1] = s * local[i, 0] + c * local[i, 1] + y


@jit
def _clear(node, clear, cells, nk, C, geo, locals_, radii, walls, obsts, verts, rule,
           robots, order, scratch):
    """Clearance of ``node``, computed on first use (``clear`` holds NaN until then)."""
    v = clear[node]
    if v == v:
        return v
    k = node % nk
    cell = (node // nk) % C
    layer = node // (nk * C)
    x, y = cells[cell, 0], cells[cell, 1]
    _place(locals_[layer], x, y, -math.pi + k * geo[1], robots)
    v = robots_clearance(robots, walls, obsts[layer], verts, rule, x, y, radii[layer], order,
                         scratch)
    clear[node] = v
    return v


@jit
def _push(heap, g, parent, q, node, cost, x, y, goal_xy, speed):
    """Relax node ``q`` reached from ``node`` at ``cost`` (its pose at ``(x, y)``)."""
    g[q], parent[q] = cost, node
    dist = math.sqrt((x - goal_xy[0]) ** 2 + (y - goal_xy[1]) ** 2)
    heapq.heappush(heap, (cost + dist / speed, q))


@jit
def _rigid_moves(node, c0, heap, g, parent, done, clear, cells, nbr, nk, geo, locals_,
                 radii, walls, obsts, verts, rule, motion, goal_xy, work, weight):
    """Relax the 26 lattice neighbours of ``node`` in its layer (module docstring)."""
    C = cells.shape[0]
    dpsi = geo[1]
    speed, omega, margin, min_step, need = motion[0], motion[1], motion[2], motion[3], motion[4]
    robots, order, scratch, a, b = work[0], work[1], work[2], work[3], work[4]
    k = node % nk
    cell = (node // nk) % C
    layer = node // (nk * C)
    x, y, psi = cells[cell, 0], cells[cell, 1], -math.pi + k * dpsi
    for m in range(9):
        c2 = cell if m == 8 else nbr[cell, m]
        if c2 < 0:
            continue
        move = math.sqrt((cells[c2, 0] - x) ** 2 + (cells[c2, 1] - y) ** 2)
        for dk in range(-1, 2):
            if m == 8 and dk == 0:
                continue
            q = (layer * C + c2) * nk + (k + dk) % nk
            if done[q]:
                continue
            cq = _clear(q, clear, cells, nk, C, geo, locals_, radii, walls, obsts, verts,
                        rule, robots, order, scratch)
            if cq < need:
                continue
            if c0 + cq - move - radii[layer] * dpsi * abs(dk) < 2.0 * margin:
                a[0], a[1], a[2] = x, y, psi
                b[0], b[1], b[2] = cells[c2, 0], cells[c2, 1], psi + dk * dpsi
                if motion_clear(locals_[layer], radii[layer], walls, obsts[layer], verts,
                                rule, a, b, margin, min_step) <= 0:
                    continue
            cost = g[node] + max(move / speed, dpsi * abs(dk) / omega) * weight[layer]
            if cost < g[q]:
                _push(heap, g, parent, q, node, cost, cells[c2, 0], cells[c2, 1], goal_xy,
                      speed)


@jit
def _changes(node, heap, g, parent, done, clear, cells, nk, geo, locals_, radii, walls,
             obsts, verts, rule, motion, change_cost, change_obst, goal_xy, work):
    """Relax the same pose of every other layer that ``node``'s layer may change to."""
    C = cells.shape[0]
    margin, min_step, need = motion[2], motion[3], motion[4]
    robots, order, scratch, other = work[0], work[1], work[2], work[5]
    k = node % nk
    cell = (node // nk) % C
    layer = node // (nk * C)
    x, y, psi = cells[cell, 0], cells[cell, 1], -math.pi + k * geo[1]
    for m in range(locals_.shape[0]):
        if m == layer or not change_cost[layer, m] < np.inf:
            continue
        q = (m * C + cell) * nk + k
        cost = g[node] + change_cost[layer, m]
        if done[q] or not cost < g[q]:
            continue
        if _clear(q, clear, cells, nk, C, geo, locals_, radii, walls, obsts, verts, rule,
                  robots, order, scratch) < need:
            continue
        _place(locals_[layer], x, y, psi, robots)
        _place(locals_[m], x, y, psi, other)
        if morph_clear(robots, other, x, y, max(radii[layer], radii[m]), walls,
                       change_obst[layer, m], verts, rule, margin, min_step) > 0:
            _push(heap, g, parent, q, node, cost, x, y, goal_xy, motion[0])


@jit
def lattice_astar(cells, nbr, nk, geo, locals_, radii, walls, obsts, verts, rule, motion,
                  change_cost, change_obst, starts, goal_nodes, goal_cost, goal_xy,
                  max_expansions, weight):
    """A* from the ``starts`` node ids to the goal (module docstring).

    ``cells`` (C, 2) cell positions; ``nbr`` (C, 8) neighbour cells in ``OFFSETS`` order
    (-1: none); ``geo`` = (spacing, dpsi); ``locals_`` (L, N, 2) formations; ``radii``
    (L,); ``obsts`` (L, O, OBST_COLS) each layer's obstacle rows; ``motion`` = (speed, rotation
    speed, margin, least advance, least clearance of a node); ``change_cost`` (L, L)
    seconds (inf: not allowed); ``change_obst`` (L, L, O, OBST_COLS) the obstacle rows during a
    change; ``goal_nodes`` sorted node ids joined to the goal at ``goal_cost`` seconds.
    Returns ``(path node ids from a start to the last node before the goal, seconds,
    expansions)``; the path is empty when the goal is not reached within
    ``max_expansions``."""
    L, N = locals_.shape[0], locals_.shape[1]
    C = cells.shape[0]
    total = L * C * nk
    g = np.full(total, np.inf)
    parent = np.full(total, -1, np.int64)
    clear = np.full(total, np.nan, np.float32)
    done = np.zeros(total, np.bool_)
    work = (np.empty((N, 2)), np.empty(N, np.int64), np.empty((N + 1, 2)), np.empty(3),
            np.empty(3), np.empty((N, 2)))
    heap = [(0.0, np.int64(0))]
    heap.pop()
    for s in starts:
        g[s] = 0.0
        heapq.heappush(heap, (0.0, s))
    best_goal, best_cost, expanded = np.int64(-1), np.inf, 0
    while heap:
        f, node = heapq.heappop(heap)
        if f >= best_cost:
            break
        if done[node]:
            continue
        done[node] = True
        expanded += 1
        if expanded > max_expansions:
            break
        gi = np.searchsorted(goal_nodes, node)
        if gi < len(goal_nodes) and goal_nodes[gi] == node:
            if g[node] + goal_cost[gi] < best_cost:
                best_cost, best_goal = g[node] + goal_cost[gi], node
        c0 = _clear(node, clear, cells, nk, C, geo, locals_, radii, walls, obsts, verts,
                    rule, work[0], work[1], work[2])
        _rigid_moves(node, c0, heap, g, parent, done, clear, cells, nbr, nk, geo, locals_,
                     radii, walls, obsts, verts, rule, motion, goal_xy, work, weight)
        _changes(node, heap, g, parent, done, clear, cells, nk, geo, locals_, radii, walls,
                 obsts, verts, rule, motion, change_cost, change_obst, goal_xy, work)
    if best_goal < 0:
        return np.zeros(0, np.int64), np.inf, expanded
    path = [best_goal]
    while parent[path[-1]] >= 0:
        path.append(parent[path[-1]])
    return np.array(path[::-1]), best_cost, expanded
