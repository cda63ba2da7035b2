"""numba, when installed, with an on-disk cache that works in read-only installs.

:func:`jit` is ``numba.njit(cache=True, nogil=True, error_model="numpy")`` (float
division by zero gives inf/NaN as in numpy) or, without numba, the plain function.

numba invalidates a cached function when *its own* source file changes, not when a
compiled function it calls from another module does (e.g. ``taut.plan._kernels.lattice``
calling ``taut.plan._kernels.clearance``). An install writes every file anew, so this only bites
a working tree in which a kernel was edited: ``make clean-cache`` removes the cached
machine code (``*.nbi``, ``*.nbc``).
"""

from __future__ import annotations

import os
import tempfile
from typing import Any, Callable

try:  # numba is a core dependency; without it (no wheel for this Python) numpy is used.
    if os.environ.get("TAUT_DISABLE_NUMBA"):
        raise ImportError("disabled by TAUT_DISABLE_NUMBA")
    import numba
except ImportError:  # pragma: no cover - depends on the environment
    numba = None  # type: ignore[assignment]

#: True when the compiled path is available.
HAVE_NUMBA = numba is not None


def _writable(directory: str) -> bool:
    """Whether a file can be created in ``directory`` (created if missing)."""
    try:
        os.makedirs(directory, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            return True
    except OSError:
        return False


def _ensure_cache_dir() -> None:
    """numba caches next to this file (``__pycache__``) or in the user's cache directory;
    when neither is writable (a read-only install for a user without a home) and
    ``NUMBA_CACHE_DIR`` is not set, use a per-user directory under the system's
    temporary directory, so that ``cache=True`` never fails."""
    if numba is None or os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "__pycache__")
    if _writable(here):
        return
    user = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"),
                        "numba")
    if _writable(user):
        return
    fallback = os.path.join(tempfile.gettempdir(), f"taut-numba-cache-{os.getuid()}")
    numba.config.CACHE_DIR = fallback  # type: ignore[attr-defined]


_ensure_cache_dir()


def jit(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit(cache=True)`` when numba is available, else ``fn`` itself."""
    if numba is None:  # pragma: no cover - depends on the environment
        return fn
    return numba.njit(cache=True, nogil=True, error_model="numpy")(fn)
