"""Reading a sweep's ``results.parquet`` back: only the columns and rows asked for, at once
(:func:`read_results`) or batch by batch (:func:`iter_results`), and its metadata.

The file is written in row groups (:data:`taut.sweep.store.ROW_GROUP_ROWS` rows), so a row
range reads only the row groups it overlaps and a column list only those columns. The file is
plain Parquet: pandas, Polars and DuckDB read it too.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import as_count, as_path
from ..errors import SweepError
from .store import ROW_GROUP_ROWS

__all__ = ["read_results", "iter_results", "results_columns"]


def _open(folder: str | Path) -> tuple[Any, Path]:
    path = as_path(folder, "folder") / "results.parquet"
    if not path.is_file():
        raise SweepError("folder", f"{folder} holds no results.parquet (run `taut sweep` "
                         "first)")
    try:
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - depends on the install
        raise SweepError("sweep", "needs pyarrow: pip install 'taut[sweep]'") from None
    try:
        return pq.ParquetFile(path), path
    except (OSError, ValueError) as exc:        # pyarrow's ArrowInvalid is a ValueError
        raise _damaged(path, exc) from None


def _damaged(path: Path, exc: Exception) -> SweepError:
    return SweepError("folder", f"{path} is damaged ({exc.__class__.__name__}); run the "
                      "sweep again with --resume to rebuild it")


def _names(pf: Any, columns: Sequence[str] | None) -> list[str]:
    names = list(pf.schema_arrow.names)
    if columns is None:
        return names
    if isinstance(columns, str) or not all(isinstance(c, str) for c in columns):
        raise SweepError("columns", "must be a list of column names")
    for c in columns:
        if c not in names:
            raise SweepError("columns", f"no column {c!r} in the results; columns: "
                             f"{', '.join(names)}")
    return list(dict.fromkeys(columns))


def _meta(pf: Any) -> dict[str, str]:
    return {k.decode(): v.decode() for k, v in (pf.schema_arrow.metadata or {}).items()
            if not k.startswith(b"ARROW")}


def _numpy(table: Any) -> dict[str, np.ndarray]:
    return {name: np.asarray(table.column(name).to_numpy(zero_copy_only=False))
            for name in table.column_names}


def results_columns(folder: str | Path) -> tuple[list[str], dict[str, str], int]:
    """Column names, metadata and row count of a results folder (reads the footer only).

    Raises
    ------
    SweepError
        No ``results.parquet`` in ``folder``, a damaged one, or pyarrow missing.
    """
    pf, _ = _open(folder)
    return list(pf.schema_arrow.names), _meta(pf), int(pf.metadata.num_rows)


def read_results(folder: str | Path, columns: Sequence[str] | None = None,
                 rows: tuple[int, int] | None = None
                 ) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Columns (name -> array, strings as object arrays) and metadata of a results folder.

    Parameters
    ----------
    folder : path
        Results folder of :func:`~taut.sweep.run_sweep`.
    columns : list of str, optional
        Only these columns (default: all).
    rows : (int, int), optional
        Only rows ``start..stop-1`` (default: all); only the row groups they overlap are read.

    Raises
    ------
    SweepError
        No ``results.parquet`` in ``folder``, a damaged one, an unknown column, a bad row
        range, or pyarrow missing.
    """
    pf, path = _open(folder)
    names = _names(pf, columns)
    total = int(pf.metadata.num_rows)
    start, stop = (0, total) if rows is None else _row_range(rows, total)
    try:
        groups, first, at = [], None, 0
        for g in range(pf.metadata.num_row_groups):
            n = pf.metadata.row_group(g).num_rows
            if at < stop and at + n > start:
                groups.append(g)
                first = at if first is None else first
            at += n
        table = pf.read_row_groups(groups, columns=names) if groups else \
            pf.schema_arrow.empty_table().select(names)
    except (OSError, ValueError) as exc:
        raise _damaged(path, exc) from None
    if groups:
        table = table.slice(start - (first or 0), stop - start)
    return _numpy(table), _meta(pf)


def _row_range(rows: Any, total: int) -> tuple[int, int]:
    if not isinstance(rows, (tuple, list)) or len(rows) != 2:
        raise SweepError("rows", "must be (start, stop)")
    start = as_count(rows[0], "rows", minimum=0, maximum=total)
    stop = as_count(rows[1], "rows", minimum=start, maximum=total)
    return start, stop


def iter_results(folder: str | Path, columns: Sequence[str] | None = None,
                 batch_rows: int = ROW_GROUP_ROWS) -> Iterator[dict[str, np.ndarray]]:
    """The rows of a results folder, in order, as column batches of at most ``batch_rows``
    rows: memory is that of one batch whatever the sweep's size.

    Raises
    ------
    SweepError
        As :func:`read_results`.
    """
    pf, path = _open(folder)
    names = _names(pf, columns)
    batch_rows = as_count(batch_rows, "batch_rows", minimum=1)
    try:
        for batch in pf.iter_batches(batch_size=batch_rows, columns=names):
            yield _numpy(batch)
    except (OSError, ValueError) as exc:
        raise _damaged(path, exc) from None
