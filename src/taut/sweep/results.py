"""Reading a sweep's ``results.parquet`` back as numpy columns and its metadata."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._validate import as_path
from ..errors import SweepError

__all__ = ["read_results"]


def read_results(folder: str | Path) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Columns (name -> array, strings as object arrays) and metadata of a results folder.

    Raises
    ------
    SweepError
        No ``results.parquet`` in ``folder``, a damaged one, or pyarrow missing.
    """
    path = as_path(folder, "folder") / "results.parquet"
    if not path.is_file():
        raise SweepError("folder", f"{folder} holds no results.parquet (run `taut sweep` "
                         "first)")
    try:
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - depends on the install
        raise SweepError("sweep", "needs pyarrow: pip install 'taut[sweep]'") from None
    try:
        table = pq.read_table(path)
    except (OSError, ValueError) as exc:        # pyarrow's ArrowInvalid is a ValueError
        raise SweepError("folder", f"{path} is damaged ({exc.__class__.__name__}); run the "
                         "sweep again with --resume to rebuild it") from None
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()
            if not k.startswith(b"ARROW")}
    columns = {name: np.asarray(table.column(name).to_numpy(zero_copy_only=False))
               for name in table.column_names}
    return columns, meta
