"""A sweep's results folder: one Parquet file per finished chunk, a manifest naming the
sweep, and the assembled ``results.parquet``.

Every file is written to a temporary name and renamed into place, so a file that exists is
complete: an interrupted run loses at most the chunks in flight, and a resumed run skips
every chunk file present. This is the only module of :mod:`taut.sweep` that touches files.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SweepError

__all__ = ["Store", "to_table", "METADATA_KEYS"]

#: Keys of the Parquet schema metadata of ``results.parquet``.
METADATA_KEYS = ("taut_version", "sweep_digest", "sweep_task", "sweep_source")


def _pa() -> Any:
    try:
        import pyarrow
        import pyarrow.parquet  # noqa: F401
    except ImportError:  # pragma: no cover - depends on the install
        raise SweepError("sweep", "needs pyarrow: pip install 'taut[sweep]'") from None
    return pyarrow


def to_table(columns: dict[str, np.ndarray]) -> Any:
    """A ``pyarrow.Table`` with typed columns (int64, float64, bool, string)."""
    pa = _pa()
    arrays = {}
    for name, col in columns.items():
        col = np.asarray(col)
        if col.dtype == object:
            arrays[name] = pa.array([str(v) for v in col], type=pa.string())
        else:
            arrays[name] = pa.array(col)
    return pa.table(arrays)


def _atomic_write(path: Path, write: Any) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    write(tmp)
    os.replace(tmp, path)


class Store:
    """The results folder of one sweep.

    Parameters
    ----------
    root : path
        Folder (created if missing).
    digest : str
        The sweep's :attr:`~taut.sweep.SweepSpec.digest`.
    resume : bool
        Continue a run of the same sweep found in the folder.

    Raises
    ------
    SweepError
        The folder is a file or not writable, holds results of a different sweep, or holds
        results of this sweep and ``resume`` is false.
    """

    def __init__(self, root: str | Path, digest: str, *, resume: bool) -> None:
        self.root = Path(root)
        self.digest = digest
        if self.root.exists() and not self.root.is_dir():
            raise SweepError("out", f"{self.root} is a file, not a folder")
        manifest = self.root / "manifest.json"
        if manifest.is_file():
            try:
                found = json.loads(manifest.read_text(encoding="utf-8")).get("sweep_digest")
            except (OSError, ValueError):
                found = None
            if found != digest:
                raise SweepError("out", f"{self.root} holds results of a different sweep; "
                                 "choose another folder")
            if not resume:
                raise SweepError("out", f"{self.root} already holds results of this sweep; "
                                 "pass --resume to continue it or choose another folder")
        self._manifest = manifest
        parent = self.root if self.root.exists() else self.root.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not os.access(parent, os.W_OK):
            raise SweepError("out", f"cannot write to {parent}")

    def _ensure(self) -> None:
        """Create the folder and its manifest on the first write."""
        if self._manifest.is_file():
            return
        try:
            (self.root / "chunks").mkdir(parents=True, exist_ok=True)
            _atomic_write(self._manifest, lambda p: p.write_text(
                json.dumps({"sweep_digest": self.digest}) + "\n", encoding="utf-8"))
        except OSError as exc:
            raise SweepError("out", f"cannot write to {self.root} ({exc.strerror})") from None

    def chunk_path(self, index: int) -> Path:
        """File of chunk ``index``."""
        return self.root / "chunks" / f"chunk-{index:07d}.parquet"

    def has(self, index: int) -> bool:
        """Whether chunk ``index`` is finished."""
        return self.chunk_path(index).is_file()

    def write_chunk(self, index: int, columns: dict[str, np.ndarray]) -> None:
        """Store a finished chunk (atomically)."""
        pq = _pa().parquet
        table = to_table(columns)
        self._ensure()
        _atomic_write(self.chunk_path(index), lambda p: pq.write_table(table, p))

    def assemble(self, indices: list[int], rows: int, metadata: dict[str, str]) -> Path:
        """Concatenate chunks ``indices`` in order, keep the first ``rows`` rows and write
        ``results.parquet`` with ``metadata``; returns its path."""
        pa = _pa()
        pq = pa.parquet
        self._ensure()
        tables = [pq.read_table(self.chunk_path(i)) for i in indices]
        table = pa.concat_tables(tables).slice(0, rows)
        meta = dict(table.schema.metadata or {})
        meta.update({k.encode(): v.encode() for k, v in metadata.items()})
        table = table.replace_schema_metadata(meta)
        out = self.root / "results.parquet"
        _atomic_write(out, lambda p: pq.write_table(table, p))
        return out
