"""Small helpers shared by the sheet modules (one copy each).

* :data:`Q_SIGNS` / :func:`q_hessian` -- the Hessian of :math:`q(x) = |r_o|^2 - |v_o|^2`
  up to the factor 2, ``diag(1, 1, -1, -1)`` (docs/sheet_kinematics.md §5);
* :func:`combo_table` -- every ``k``-subset of ``range(n)`` as a cached, read-only table.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

__all__ = ["Q_SIGNS", "q_hessian", "combo_table"]

#: Diagonal of the Hessian of q (docs/sheet_kinematics.md §5), up to the factor 2 (which
#: changes no sign): (+1, +1, -1, -1) over :math:`x = (\\mathbf{r}_o, \\mathbf{v}_o)`.
Q_SIGNS = np.array([1.0, 1.0, -1.0, -1.0])
Q_SIGNS.flags.writeable = False


def q_hessian() -> np.ndarray:
    """``diag(1, 1, -1, -1)``, shape (4, 4): the Hessian of q over 2 (a fresh array)."""
    return np.diag(Q_SIGNS)


_COMBOS: dict[tuple[int, int], np.ndarray] = {}


def combo_table(n: int, k: int) -> np.ndarray:
    """All ``k``-subsets of ``range(n)`` in lexicographic order, shape (C(n, k), k).

    Cached and read-only (copy before writing).

    Examples
    --------
    >>> combo_table(4, 3).tolist()
    [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
    """
    key = (n, k)
    table = _COMBOS.get(key)
    if table is None:
        table = np.array(list(combinations(range(n), k)), dtype=np.intp).reshape(-1, k)
        table.flags.writeable = False
        _COMBOS[key] = table
    return table
