"""The deformable sheet and the checks on a robot formation (FK paper, Sec. II)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._validate import MAX_ROBOTS, MAX_SHEET_LENGTH, as_array, as_points, as_positive, check_range
from ..errors import InfeasibleFormationError, InvalidInputError, InvalidSheetError
from ._tol import GEOMETRY_RTOL, WINDING_TOL
from .._validate import require_instance

__all__ = ["Sheet", "check_formation", "check_formations", "check_hold_height"]



@dataclass(frozen=True, eq=False)
class Sheet:
    """A deformable, inelastic sheet whose vertices are held by the robots.

    The sheet's flat shape is a convex polygon :math:`\\mathcal{V}_N^0` (FK paper, Sec. II);
    robot ``i`` holds vertex ``i``. Vertices may be listed clockwise or counter-clockwise.
    Lengths in any consistent unit (the unit of the formation and hold height).

    Parameters
    ----------
    vertices : array_like, shape (N, 2)
        Vertex positions :math:`\\mathbf{v}_i` in the sheet frame :math:`\\mathcal{W}_S`,
        in robot order, ``N >= 3``.

    Raises
    ------
    InvalidSheetError
        Fewer than 3 vertices, NaN/inf, repeated vertices, a non-convex or
        self-intersecting polygon, or all vertices on a line. Vertices lying on an edge
        between their neighbours (a robot holding the middle of a side) are allowed.
    """

    vertices: np.ndarray
    size: float = field(init=False)
    orientation: str = field(init=False)
    has_collinear_vertices: bool = field(init=False)

    def __post_init__(self) -> None:
        try:
            v = as_points(self.vertices, "sheet", min_count=3)
            check_range(v, "sheet", MAX_SHEET_LENGTH, "sheet units")
            if len(v) > MAX_ROBOTS:
                raise InvalidInputError("sheet", f"{len(v)} vertices exceeds {MAX_ROBOTS}")
        except InvalidInputError as exc:
            raise InvalidSheetError(exc.field, exc.problem) from None
        centre = v.mean(axis=0)
        size = float(np.max(np.linalg.norm(v - centre, axis=1)))
        if size == 0.0:
            raise InvalidSheetError("sheet", "all vertices coincide")
        tol = GEOMETRY_RTOL * size
        n = len(v)
        edges = np.roll(v, -1, axis=0) - v
        lengths = np.linalg.norm(edges, axis=1)
        if np.any(lengths <= tol):
            i = int(np.argmax(lengths <= tol))
            raise InvalidSheetError(f"sheet[{(i + 1) % n}]",
                                    f"repeats vertex {i} (sheet vertices must be distinct)")
        d = v[:, None, :] - v[None, :, :]
        dist = np.linalg.norm(d, axis=2) + np.eye(n) * (size + 1.0)
        if np.any(dist <= tol):
            i, j = np.argwhere(dist <= tol)[0]
            raise InvalidSheetError(f"sheet[{j}]", f"repeats vertex {i} (sheet vertices must be distinct)")
        # cross[i]: z-component of edge_{i-1} x edge_i, the turn at vertex i.
        prev = np.roll(edges, 1, axis=0)
        cross = prev[:, 0] * edges[:, 1] - prev[:, 1] * edges[:, 0]
        ctol = tol * (lengths + np.roll(lengths, 1))
        turns = np.where(np.abs(cross) <= ctol, 0, np.sign(cross))
        if np.all(turns == 0):
            raise InvalidSheetError("sheet", "all vertices lie on one line")
        sign = turns[turns != 0][0]
        if np.any(turns == -sign):
            i = int(np.argmax(turns == -sign))
            raise InvalidSheetError(f"sheet[{i}]", "polygon is not convex at this vertex "
                                    "(vertices must go around a convex polygon in order)")
        # Consistent turn direction but winding more than once: self-intersecting (a star).
        angles = np.arctan2(cross, np.einsum("ij,ij->i", prev, edges))
        if abs(abs(angles.sum()) - 2 * np.pi) > WINDING_TOL:
            raise InvalidSheetError("sheet", "polygon is self-intersecting (it winds around "
                                    "more than once)")
        v.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "orientation", "ccw" if sign > 0 else "cw")
        object.__setattr__(self, "has_collinear_vertices", bool(np.any(turns == 0)))

    @classmethod
    def regular(cls, n: int, circumradius: float, *, phase: float = 0.0) -> "Sheet":
        """Regular ``n``-gon with vertex ``i`` (0-based) at angle ``phase + 2 pi i / n``.

        As in the FK paper's Examples 2 and 6 (octagon, :math:`r_s = 0.9` m).
        """
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or not 3 <= n <= MAX_ROBOTS:
            raise InvalidSheetError("n", f"must be an integer in [3, {MAX_ROBOTS}], got {n!r}")
        r = as_positive(circumradius, "circumradius")
        t = phase + 2 * np.pi * np.arange(n) / n
        return cls(np.column_stack([r * np.cos(t), r * np.sin(t)]))

    @property
    def n(self) -> int:
        """Number of vertices (= number of robots)."""
        return int(self.vertices.shape[0])

    @property
    def centroid(self) -> np.ndarray:
        """Area centroid of the polygon, shape (2,)."""
        v = self.vertices
        w = np.roll(v, -1, axis=0)
        c = v[:, 0] * w[:, 1] - w[:, 0] * v[:, 1]
        a = c.sum() / 2
        return np.array([((v[:, 0] + w[:, 0]) * c).sum(), ((v[:, 1] + w[:, 1]) * c).sum()]) / (6 * a)

    @property
    def area(self) -> float:
        """Polygon area (positive), in length units squared."""
        v = self.vertices
        w = np.roll(v, -1, axis=0)
        return float(abs((v[:, 0] * w[:, 1] - w[:, 0] * v[:, 1]).sum()) / 2)

    def side_lengths(self) -> np.ndarray:
        """Pairwise vertex distances :math:`|\\mathbf{v}_i - \\mathbf{v}_j|`, shape (N, N)."""
        d = self.vertices[:, None, :] - self.vertices[None, :, :]
        return np.linalg.norm(d, axis=2)

    def contains(self, point: ArrayLike, *, tol: float = GEOMETRY_RTOL) -> np.ndarray:
        """Whether points (..., 2) lie in the closed polygon (tolerance relative to size)."""
        p = np.asarray(point, dtype=float)
        v = self.vertices
        e = np.roll(v, -1, axis=0) - v
        rel = p[..., None, :] - v
        cross = e[:, 0] * rel[..., 1] - e[:, 1] * rel[..., 0]
        if self.orientation == "cw":
            cross = -cross
        return np.all(cross >= -tol * self.size * np.linalg.norm(e, axis=1), axis=-1)

    def __repr__(self) -> str:
        return f"Sheet(n={self.n}, size={self.size:g}, orientation={self.orientation!r})"


def check_hold_height(hold_height: float) -> float:
    """Validate the holding height :math:`z_r` (> 0, finite)."""
    z = as_positive(hold_height, "hold_height")
    check_range(z, "hold_height", MAX_SHEET_LENGTH, "sheet units")
    return z


def _formation_batch(sheet: Sheet, formations: ArrayLike, field: str) -> np.ndarray:
    """``formations`` as a finite float64 array of shape (B, N, 2) for ``sheet``, or an
    :class:`InvalidInputError` (wrong shape or robot count, NaN/inf, out of range)."""
    require_instance(sheet, Sheet, "sheet")
    r = check_range(as_array(formations, field, ndim=3), field, MAX_SHEET_LENGTH, "sheet units")
    if r.shape[2] != 2:
        raise InvalidInputError(field, f"last axis must have length 2 (x, y), got {r.shape[2]}")
    if r.shape[1] != sheet.n:
        raise InvalidInputError(field, f"has {r.shape[1]} robots but the sheet has "
                                       f"{sheet.n} vertices")
    return r


def _pair_limits(sheet: Sheet) -> np.ndarray:
    """Largest accepted distance of each robot pair, shape (N, N): the sheet distance
    widened by ``GEOMETRY_RTOL`` (relative, and of the sheet size)."""
    return sheet.side_lengths() * (1 + GEOMETRY_RTOL) + GEOMETRY_RTOL * sheet.size


def _torn_pairs(sheet: Sheet, r: np.ndarray) -> np.ndarray:
    """Bool (B, P): which robot pairs (``numpy.triu_indices`` order) of the validated
    formations ``r`` (B, N, 2) stand farther apart than their sheet vertices allow."""
    iu, ju = np.triu_indices(sheet.n, 1)
    lim2 = _pair_limits(sheet)[iu, ju] ** 2
    torn = np.zeros((r.shape[0], len(iu)), dtype=bool)
    # Chunks keep the (chunk, pairs, 2) temporaries small (fresh large arrays are slow).
    step = max(1, (1 << 18) // max(len(iu), 1))
    for start in range(0, r.shape[0], step):
        chunk = r[start:start + step]
        diff = chunk[:, iu, :] - chunk[:, ju, :]
        torn[start:start + step] = np.einsum("bpk,bpk->bp", diff, diff) > lim2
    return torn


def feasible_formations(sheet: Sheet, formations: ArrayLike, field: str = "formations"
                        ) -> np.ndarray:
    """Which formations of a batch (B, N, 2) the sheet can span (the paper's
    ``FormationFeasible``, as :func:`check_formations`), as a bool array of shape (B,).

    Raises
    ------
    InvalidInputError
        Wrong shape, robot count different from the sheet's, NaN/inf.
    """
    torn = _torn_pairs(sheet, _formation_batch(sheet, formations, field))
    return np.asarray(~torn.any(axis=1))


def check_formations(sheet: Sheet, formations: ArrayLike, field: str = "formations"
                     ) -> np.ndarray:
    """Validate a batch of formations, shape (B, N, 2), against the sheet.

    Implements the paper's ``FormationFeasible`` (Algorithm 1): the sheet is inelastic, so
    robots ``i`` and ``j`` may be at most :math:`|\\mathbf{v}_i - \\mathbf{v}_j|` apart
    (a relative tolerance of 1e-9 of the sheet size absorbs rounding).

    Raises
    ------
    InvalidInputError
        Wrong shape, robot count different from the sheet's, NaN/inf.
    InfeasibleFormationError
        Some pair of robots is farther apart than its sheet vertices; ``step`` holds the
        batch index for batched input.
    """
    r = _formation_batch(sheet, formations, field)
    torn = _torn_pairs(sheet, r)
    if torn.any():
        b, p = (int(k) for k in np.argwhere(torn)[0])
        iu, ju = np.triu_indices(sheet.n, 1)
        i, j = int(iu[p]), int(ju[p])
        limit = _pair_limits(sheet)[i, j]
        at: int | None = b if r.shape[0] > 1 else None
        where = f" at step {at}" if at is not None else ""
        raise InfeasibleFormationError(
            field,
            f"robots {i + 1} and {j + 1} are {np.linalg.norm(r[b, i] - r[b, j]):.6g} apart"
            f"{where} but their sheet vertices only {limit / (1 + GEOMETRY_RTOL):.6g} "
            "(the sheet would tear)",
            pair=(i, j), step=at)
    return r


def check_formation(sheet: Sheet, formation: ArrayLike, field: str = "formation"
                    ) -> np.ndarray:
    """Validate one formation, shape (N, 2); see :func:`check_formations`."""
    require_instance(sheet, Sheet, "sheet")
    r = as_array(formation, field, ndim=2)
    return check_formations(sheet, r[None], field)[0]
