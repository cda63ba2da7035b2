"""A sweep's results folder: one Parquet file per finished chunk, a manifest naming the
sweep, and ``results.parquet``, the chunks streamed into one file in row groups of
:data:`ROW_GROUP_ROWS` rows.

Every file is written to a temporary name and renamed into place, so a file that exists is
complete: an interrupted run loses at most the chunks in flight. Each chunk has a SHA-256
checksum beside it (``chunk-NNNNNNN.parquet.sha256``); a resumed run skips only chunks
whose file matches its checksum and recomputes any other (truncated, damaged, or written
by a version without checksums).

One writer per folder: a run holds ``DIR/.lock`` (naming its process, host and start
time) from start to end, and a second run on the same folder is refused with a line
naming the holder; a lock left by a process that no longer runs on this host is taken
over. Every chunk write re-reads the manifest and stops if the folder has been given to
another sweep. This is the only module of :mod:`taut.sweep` that touches files.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import socket
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..errors import SweepError

__all__ = ["Store", "to_table", "METADATA_KEYS"]

#: Keys of the Parquet schema metadata of ``results.parquet``.
METADATA_KEYS = ("taut_version", "sweep_digest", "sweep_task", "sweep_source")
#: Rows per row group of ``results.parquet``: the unit in which it is written and read back
#: (about 5 MB for ten float columns).
ROW_GROUP_ROWS = 1 << 16
#: First and last bytes of every Parquet file (a file without them at its end was cut).
_PARQUET_MAGIC = b"PAR1"


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
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


#: Signals whose Python handlers :func:`_uninterrupted` holds back: Ctrl-C, and the alarm
#: by which the CLI raises a swallowed interrupt again (:mod:`taut.cli`).
_DEFERRED = tuple(getattr(signal, name) for name in ("SIGINT", "SIGALRM")
                  if hasattr(signal, name))


@contextmanager
def _uninterrupted() -> Iterator[None]:
    """Run the block whole: a Ctrl-C (or the CLI's repeat alarm) arriving inside it is
    held and sent again when the block ends, to the disposition that was in place (in the
    CLI a ``KeyboardInterrupt`` then). Only the main thread receives signals; elsewhere,
    and for a signal whose handler was not installed from Python, the block runs as is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous = {s: signal.signal(s, lambda signum, frame: held.append(signum))
                for s in _DEFERRED if signal.getsignal(s) is not None}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        for s in held:
            signal.raise_signal(s)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


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
        self._locked = False
        self._created = not self.root.exists()
        if self.root.exists() and not self.root.is_dir():
            raise SweepError("out", f"{self.root} is a file, not a folder")
        manifest = self.root / "manifest.json"
        self._manifest = manifest
        self._lock()
        try:
            self._check_folder(manifest, digest, resume)
        except BaseException:
            self.close()
            raise

    # --- the lock -----------------------------------------------------------------
    def _lock(self) -> None:
        """Take ``DIR/.lock`` (see the module docstring)."""
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SweepError("out", f"cannot create {self.root} ({exc.strerror})") from None
        lock = self.root / ".lock"
        me = {"pid": os.getpid(), "host": socket.gethostname(),
              "started": time.strftime("%Y-%m-%d %H:%M:%S %Z")}
        # The lock appears with its holder already written (a complete temporary file
        # hard-linked into place, which fails if the lock exists): a lock created empty and
        # filled afterwards could be read empty by a second sweep, taken for a dead one's,
        # and taken over -- two writers in one folder.
        mine = self.root / f".lock.{os.getpid()}.tmp"
        for _ in range(3):
            try:
                mine.write_text(json.dumps(me), encoding="utf-8")
                os.link(mine, lock)
            except FileExistsError:
                try:
                    holder = json.loads(lock.read_text(encoding="utf-8"))
                except (OSError, ValueError):
                    holder = {}
                pid, host = holder.get("pid"), holder.get("host")
                if (host == me["host"] and isinstance(pid, int) and not _alive(pid)) \
                        or not holder:
                    lock.unlink(missing_ok=True)          # left by a process now gone
                    continue
                raise SweepError("out", f"{self.root} is being written by another sweep "
                                 f"(process {pid} on {host}, since {holder.get('started')});"
                                 " wait for it to finish or choose another folder") from None
            except OSError as exc:
                raise SweepError("out", f"cannot write to {self.root} ({exc.strerror})"
                                 ) from None
            finally:
                mine.unlink(missing_ok=True)
            self._locked = True
            return
        raise SweepError("out", f"cannot take the lock {lock}")

    def close(self) -> None:
        """Release the folder's lock (idempotent); a folder this store created and left
        empty (the run failed before its first chunk) is removed: nothing was written."""
        if self._locked:
            (self.root / ".lock").unlink(missing_ok=True)
            self._locked = False
            if self._created:
                try:
                    self.root.rmdir()                 # only if empty
                except OSError:
                    pass

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _check_folder(self, manifest: Path, digest: str, resume: bool) -> None:
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
        """Whether chunk ``index`` is finished: its file matches its checksum."""
        return self.state(index) == "finished"

    def state(self, index: int) -> str:
        """What is stored of chunk ``index``: ``"finished"`` (its file matches its
        checksum), ``"not computed"`` (neither file nor checksum), or why it must be
        recomputed: ``"missing"`` (a checksum without its file), ``"no checksum"`` (a
        file without one, e.g. written by an older taut), ``"truncated"`` (not a whole
        Parquet file: its first or last 4 bytes are not ``PAR1``) or ``"checksum
        mismatch"`` (a whole file whose bytes changed)."""
        path = self.chunk_path(index)
        check = path.with_name(path.name + ".sha256")
        if not path.is_file():
            return "missing" if check.exists() else "not computed"
        try:
            expected = check.read_text(encoding="ascii").strip()
        except (OSError, ValueError):
            return "no checksum"
        try:
            if expected == _sha256(path):
                return "finished"
            with open(path, "rb") as fh:
                head = fh.read(4)
                fh.seek(max(path.stat().st_size - 4, 0))
                tail = fh.read(4)
        except OSError:
            return "truncated"
        whole = head == tail == _PARQUET_MAGIC and path.stat().st_size > 8
        return "checksum mismatch" if whole else "truncated"

    def _check_manifest(self) -> None:
        try:
            found = json.loads(self._manifest.read_text(encoding="utf-8")).get("sweep_digest")
        except (OSError, ValueError, AttributeError):
            found = None
        if found != self.digest:
            raise SweepError("out", f"{self.root} now holds another sweep's manifest; "
                             "stopped so the two do not mix")

    def write_chunk(self, index: int, columns: dict[str, np.ndarray]) -> None:
        """Store a finished chunk and its checksum (atomically), after checking that the
        folder's manifest is still this sweep's."""
        pq = _pa().parquet
        table = to_table(columns)
        self._ensure()
        self._check_manifest()
        path = self.chunk_path(index)
        # A Ctrl-C between the two files would leave a whole chunk without its checksum
        # (seen in CI: a resumed run then computes it again); the pair is written whole.
        with _uninterrupted():
            _atomic_write(path, lambda p: pq.write_table(table, p))
            digest = _sha256(path)
            _atomic_write(path.with_name(path.name + ".sha256"),
                          lambda p: p.write_text(digest + "\n", encoding="ascii"))

    def assemble(self, chunks: int, rows: int, metadata: dict[str, str]) -> Path:
        """Write chunks ``0..chunks-1`` in order, first ``rows`` rows, to ``results.parquet``
        with ``metadata``; returns its path.

        The chunks are streamed: read one at a time and written in row groups of
        :data:`ROW_GROUP_ROWS` rows (the last one shorter), so memory is that of one row
        group and one chunk whatever the sweep's size.
        """
        pa = _pa()
        self._ensure()
        self._check_manifest()
        out = self.root / "results.parquet"

        def write(path: Path) -> None:
            writer: Any = None
            buffer: list[Any] = []
            left = rows
            try:
                for k in range(chunks):
                    if left <= 0:
                        break
                    table = pa.parquet.read_table(self.chunk_path(k))
                    table = table.slice(0, min(left, table.num_rows))
                    left -= table.num_rows
                    if writer is None:
                        meta = dict(table.schema.metadata or {})
                        meta.update({key.encode(): v.encode() for key, v in metadata.items()})
                        writer = pa.parquet.ParquetWriter(path, table.schema.with_metadata(meta))
                    buffer.append(table.cast(writer.schema))
                    if sum(t.num_rows for t in buffer) >= ROW_GROUP_ROWS:
                        joined = pa.concat_tables(buffer)
                        full = joined.num_rows - joined.num_rows % ROW_GROUP_ROWS
                        writer.write_table(joined.slice(0, full), row_group_size=ROW_GROUP_ROWS)
                        buffer = [joined.slice(full)]
                if buffer:
                    writer.write_table(pa.concat_tables(buffer), row_group_size=ROW_GROUP_ROWS)
            finally:
                if writer is not None:
                    writer.close()

        _atomic_write(out, write)
        return out
