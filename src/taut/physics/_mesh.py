"""The sheet as a node mesh: nodes, triangles and inextensibility pairs (no MuJoCo here).

The flat sheet :math:`\\mathcal{V}_N^0` (FK paper, Sec. II) is sampled by boundary nodes
(every vertex, plus points along each side at about one spacing) and interior nodes on a
triangular lattice; an optional extra node sits at a given point of the sheet (the contact
point :math:`\\mathbf{v}_o` of a state to be checked). Any two nodes may never be farther
apart in space than in the flat sheet: that is the inextensible sheet of the virtual
variable cables model (docs/sheet_kinematics.md §1), imposed here on the pairs within
``reach`` spacings.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from . import _tol

__all__ = ["SheetMesh", "sheet_mesh", "sheet_mesh_spacing", "sheet_model_size"]


@dataclass(frozen=True, eq=False)
class SheetMesh:
    """Nodes of the flat sheet and the pairs whose distance is limited.

    Attributes
    ----------
    nodes : ndarray, shape (M, 2)
        Node positions in the sheet frame, in the sheet's length unit.
    corners : ndarray of int, shape (N,)
        Node index of sheet vertex ``i`` (held by robot ``i``).
    contact : int or None
        Node index of the extra node (the contact point), if one was asked for.
    triangles : ndarray of int, shape (T, 3)
        Triangles over the nodes (for ball-sheet collision only).
    pairs : ndarray of int, shape (P, 2)
        Node pairs given a tension-only tendon.
    rest : ndarray, shape (P,)
        Flat distance of each pair (the tendon's upper length limit).
    spacing : float
        Target node spacing.
    """

    nodes: np.ndarray
    corners: np.ndarray
    contact: int | None
    triangles: np.ndarray
    pairs: np.ndarray
    rest: np.ndarray
    spacing: float


def _boundary(vertices: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    pts: list[np.ndarray] = []
    corners: list[int] = []
    n = len(vertices)
    for i in range(n):
        a, b = vertices[i], vertices[(i + 1) % n]
        k = max(1, int(round(np.linalg.norm(b - a) / spacing)))
        corners.append(int(sum(len(p) for p in pts)))
        pts.append(a + np.linspace(0.0, 1.0, k, endpoint=False)[:, None] * (b - a))
    return np.vstack(pts), np.array(corners, dtype=np.intp)


def _interior(vertices: np.ndarray, spacing: float) -> np.ndarray:
    """Triangular lattice points at least ``INTERIOR_MARGIN`` spacings inside every side."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    dy = spacing * np.sqrt(3) / 2
    rows = np.arange(lo[1], hi[1] + dy, dy)
    pts = []
    for r, y in enumerate(rows):
        x = np.arange(lo[0] + (spacing / 2 if r % 2 else 0.0), hi[0] + spacing, spacing)
        pts.append(np.column_stack([x, np.full_like(x, y)]))
    p = np.vstack(pts)
    e = np.roll(vertices, -1, axis=0) - vertices
    normal = np.column_stack([e[:, 1], -e[:, 0]]) / np.linalg.norm(e, axis=1)[:, None]
    # Signed distance of each point from each side line, made positive inwards (convex).
    dist = np.einsum("pek,ek->pe", p[:, None, :] - vertices[None], normal)
    inward = np.sign(np.einsum("ek,ek->e", vertices.mean(axis=0) - vertices, normal))
    dist = dist * inward[None, :]
    return p[np.all(dist >= _tol.INTERIOR_MARGIN * spacing, axis=1)]


def _unobstructed(nodes: np.ndarray, pairs: np.ndarray, spacing: float) -> np.ndarray:
    """Mask of pairs with no third node on the segment between them (those are implied
    by the two shorter pairs through that node)."""
    keep = np.ones(len(pairs), dtype=bool)
    a, b = nodes[pairs[:, 0]], nodes[pairs[:, 1]]
    d = b - a
    L2 = np.einsum("pk,pk->p", d, d)
    step = 512
    for s in range(0, len(pairs), step):
        rel = nodes[None, :, :] - a[s:s + step, None, :]
        t = np.einsum("pnk,pk->pn", rel, d[s:s + step]) / L2[s:s + step, None]
        foot = rel - t[..., None] * d[s:s + step, None, :]
        off = np.linalg.norm(foot, axis=2)
        inside = (t > _tol.SEGMENT_END) & (t < 1 - _tol.SEGMENT_END)
        keep[s:s + step] = ~np.any(inside & (off < _tol.ON_SEGMENT * spacing), axis=1)
    return keep


def sheet_mesh_spacing(vertices: np.ndarray, divisions: int) -> float:
    """Target node spacing: the sheet's largest vertex distance over ``divisions``."""
    V = np.asarray(vertices, dtype=float)
    return float(np.max(np.linalg.norm(V[:, None] - V[None], axis=2))) / divisions


def sheet_model_size(vertices: np.ndarray, divisions: int, *, corner_tendons: bool
                     ) -> tuple[int, int]:
    """Nodes and tendons of the sheet model, counted without building it (issue 24).

    Nodes: those of :func:`sheet_mesh` without a contact node, plus one for it. Tendons:
    the node pairs within ``TENDON_REACH`` spacings and, with ``corner_tendons``, one from
    every corner to every other node, as
    :func:`taut.physics._sheet_model.build_sheet_sim` adds them (it skips only the pairs
    already kept, so two corners farther apart than the reach get two tendons). An upper
    bound up to the contact node's few pairs: pairs with a third node on their segment
    are not dropped here. Takes O(nodes x neighbours) time and memory (a k-d tree), not
    the O(nodes^2) of the mesh itself.

    Parameters
    ----------
    vertices : ndarray, shape (N, 2)
        The sheet polygon, robot order (any length unit).
    divisions : int
        Mesh spacings across the sheet's widest vertex pair.
    corner_tendons : bool
        Count a tendon from every node to every corner.

    Returns
    -------
    nodes, tendons : int
    """
    V = np.asarray(vertices, dtype=float)
    h = sheet_mesh_spacing(V, divisions)
    bnd, corners = _boundary(V, h)
    nodes = np.vstack([bnd, _interior(V, h)])
    M, N, r = len(nodes), len(corners), _tol.TENDON_REACH * h
    tree = cKDTree(nodes)
    near = (int(tree.count_neighbors(tree, r)) - M) // 2        # ordered, self included
    return M + 1, near + (N * (M - 1) if corner_tendons else 0)


def sheet_mesh(vertices: np.ndarray, divisions: int, *, contact: np.ndarray | None = None,
               reach: float = _tol.TENDON_REACH) -> SheetMesh:
    """Mesh a convex sheet with about ``divisions`` spacings across its widest pair.

    Parameters
    ----------
    vertices : ndarray, shape (N, 2)
        The sheet polygon, robot order.
    divisions : int
        Spacing = (largest vertex distance) / ``divisions``.
    contact : ndarray, shape (2,), optional
        An extra node at this sheet point (nodes closer than half a spacing are dropped).
    reach : float
        Pairs within ``reach`` spacings get a tendon.
    """
    V = np.asarray(vertices, dtype=float)
    h = sheet_mesh_spacing(V, divisions)
    bnd, corners = _boundary(V, h)
    inner = _interior(V, h)
    nodes = np.vstack([bnd, inner])
    contact_index = None
    if contact is not None:
        c = np.asarray(contact, dtype=float)
        dist = np.linalg.norm(nodes - c, axis=1)
        hit = int(np.argmin(dist))
        if hit in set(corners.tolist()) and dist[hit] < _tol.SNAP * h:
            contact_index = hit
        else:
            drop = (dist < _tol.CONTACT_CLEARANCE * h)
            drop[corners] = False
            keep = ~drop
            new_index = np.cumsum(keep) - 1
            corners = new_index[corners]
            nodes = np.vstack([nodes[keep], c])
            contact_index = len(nodes) - 1
    tri = Delaunay(nodes).simplices
    p0, p1, p2 = nodes[tri[:, 0]], nodes[tri[:, 1]], nodes[tri[:, 2]]
    area = 0.5 * np.abs((p1 - p0)[:, 0] * (p2 - p0)[:, 1] - (p1 - p0)[:, 1] * (p2 - p0)[:, 0])
    tri = tri[area > _tol.SLIVER * h * h]
    iu, ju = np.triu_indices(len(nodes), 1)
    flat = np.linalg.norm(nodes[iu] - nodes[ju], axis=1)
    near = flat <= reach * h
    pairs = np.column_stack([iu[near], ju[near]])
    keep = _unobstructed(nodes, pairs, h)
    return SheetMesh(nodes, corners, contact_index, tri.astype(np.intp), pairs[keep],
                     flat[near][keep], h)
