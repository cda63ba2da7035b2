"""numba kernels, compiled only once their machine code is known to be cached.

A user never waits for the compiler (docs/compiled_kernels.md). Every kernel is written
once, as plain Python that numba can compile; :func:`jit` returns either
``numba.njit(cache=True, nogil=True, error_model="numpy")`` of it (float division by zero
gives inf/NaN as in numpy) or the function itself (:func:`jit_inline`: the same, inlined
into its compiled callers). The choice is made once per process,
here, from the environment variable ``TAUT_NUMBA``:

``auto`` (default)
    compiled when a *warm stamp* says that every kernel's machine code is in numba's
    on-disk cache for this taut, numba, Python, CPU and these kernel sources (a hash of
    them names the stamp). Otherwise the process runs the numpy engines (the kernels as
    plain Python where no numpy engine exists) and starts ``python -m taut._warmup``
    detached, at low priority, once: it compiles every kernel and writes the stamp, and
    later processes use the compiled code. numba itself is then not even imported.
``always``
    compiled, compiling in this process what the cache lacks (the test suite, the warmup,
    benchmarks; also ``auto`` in a process that imported numba before taut).
``never``
    never compiled (the numpy fallback, tested against the compiled engines).

:data:`HAVE_NUMBA` says which: every engine choosing between compiled and numpy code
reads it, and :func:`not_compiled_reason` says why not when it is False.

The cache sits next to the kernels (``__pycache__``) when the install is writable, else
in the user's cache directory (numba's own rule), else in a per-user directory under the
system's temporary directory, so that a read-only install works; the stamp sits in the
same place. numba invalidates a cached function when *its own* source file changes, not
when a compiled function it calls from another module does (e.g.
``taut.plan._kernels.lattice`` calling ``taut.plan._kernels.clearance``). An install
writes every file anew, so this only bites a working tree in which a kernel was edited:
``make clean-cache`` removes the cached machine code (``*.nbi``, ``*.nbc``) and stamps.
"""

from __future__ import annotations

import hashlib
import os
import platform
import sys
import tempfile
import time
from functools import lru_cache
from importlib.util import find_spec
from typing import Any, Callable, Literal

from . import __version__
from .errors import InvalidInputError, TautError

__all__ = ["MODES", "MODE", "HAVE_NUMBA", "KERNEL_SOURCES", "jit", "jit_inline",
           "not_compiled_reason", "cache_dir", "stamp_path", "is_warm", "warm_in_background",
           "compile_kernels", "LOAD_COST_S", "prefer_compiled", "charge_numpy"]

#: Values of the environment variable ``TAUT_NUMBA`` (module docstring).
MODES = ("auto", "always", "never")
#: The files compiled code is built from, relative to the package: every file holding
#: ``@jit`` kernels and the tolerance files whose constants numba freezes into them (their
#: sources key the stamp; tests/test_jit.py checks that none is missing here).
KERNEL_SOURCES = ("_jit.py", "_geometry.py", "sheet/_kernels/linalg.py",
                  "sheet/_kernels/small.py", "sheet/_kernels/batch.py", "sheet/_kernels/step.py",
                  "sheet/_tol.py", "plan/_kernels/clearance.py", "plan/_kernels/lattice.py",
                  "cdpr/control/_kernel.py", "cdpr/_tol.py")
#: A warmup started less than this long ago (s) is taken to be still running.
WARMUP_LOCK_S = 900.0
#: The background warmup this process started (:func:`warm_in_background`), if any.
_started: list[Any] = []

_PACKAGE = os.path.dirname(os.path.abspath(__file__))
MODE = os.environ.get("TAUT_NUMBA", "auto").strip().lower() or "auto"
if MODE not in MODES:
    raise InvalidInputError("TAUT_NUMBA", f"must be one of {', '.join(MODES)}, got "
                                          f"{os.environ.get('TAUT_NUMBA')!r}")
_INSTALLED = find_spec("numba") is not None


def _writable(directory: str) -> bool:
    """Whether a file can be created in ``directory`` (created if missing)."""
    try:
        os.makedirs(directory, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            return True
    except OSError:
        return False


@lru_cache(maxsize=1)
def cache_dir() -> tuple[str, bool]:
    """Where numba caches taut's kernels and the stamp lives: ``(directory, override)``;
    ``override`` is True when numba must be told (``numba.config.CACHE_DIR``).

    ``NUMBA_CACHE_DIR`` when set; the package's ``__pycache__`` when writable (numba then
    caches next to each kernel file); the user's cache directory (numba's user-wide
    locator); else a per-user directory under the system's temporary directory."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"], False
    here = os.path.join(_PACKAGE, "__pycache__")
    if _writable(here):
        return here, False
    user = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"),
                        "numba")
    if _writable(user):
        return user, False
    uid = os.getuid() if hasattr(os, "getuid") else 0
    return os.path.join(tempfile.gettempdir(), f"taut-numba-cache-{uid}"), True


def _cpu() -> bytes:
    """The CPU's model and features (numba compiles for the host CPU)."""
    try:
        with open("/proc/cpuinfo", "rb") as f:
            block = f.read(1 << 16).split(b"\n\n")[0]
        return b"\n".join(line for line in block.splitlines()
                          if line.startswith((b"model name", b"flags")))
    except OSError:
        return platform.machine().encode()


@lru_cache(maxsize=1)
def stamp_path() -> str:
    """The warm stamp of this taut, numba, Python, CPU and kernel sources (no numba
    import: numba's identity is its installed files)."""
    h = hashlib.sha256()
    h.update(f"{__version__}|{sys.version}|{sys.platform}".encode())
    spec = find_spec("numba")
    if spec is not None and spec.origin:
        st = os.stat(spec.origin)
        h.update(f"{spec.origin}|{st.st_size}|{st.st_mtime_ns}".encode())
    h.update(_cpu())
    for rel in KERNEL_SOURCES:
        with open(os.path.join(_PACKAGE, rel), "rb") as f:
            h.update(rel.encode() + b"\0" + f.read())
    return os.path.join(cache_dir()[0], f"taut-jit-{h.hexdigest()[:20]}.stamp")


def is_warm() -> bool:
    """Whether the stamp exists (the warmup finished for these sources)."""
    return _INSTALLED and os.path.exists(stamp_path())


def warm_in_background() -> bool:
    """Start ``python -m taut._warmup --background`` detached unless one started less than
    :data:`WARMUP_LOCK_S` ago (a lock file next to the stamp); True if started."""
    import subprocess

    lock = stamp_path() + ".lock"
    try:
        if time.time() - os.stat(lock).st_mtime < WARMUP_LOCK_S:
            return False
    except OSError:
        pass
    try:
        os.makedirs(os.path.dirname(lock), exist_ok=True)
        if os.path.exists(lock):
            os.remove(lock)                     # stale: its warmup died or was killed
        os.close(os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY))  # one starter wins
        child = subprocess.Popen([sys.executable, "-m", "taut._warmup", "--background"],
                                 env=dict(os.environ, TAUT_NUMBA="always"),
                                 stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL, start_new_session=True,
                                 close_fds=True)
        with open(lock, "w") as f:              # the warmup's pid (bench/bench_startup.py)
            f.write(str(child.pid))
    except OSError:
        return False
    _started.append(child)
    return True


def _stop_own_warmup() -> None:
    """Stop the background warmup this process started (``taut compile`` runs its own in
    the foreground, at normal priority, instead of racing it) and free its lock."""
    import signal
    import subprocess

    while _started:
        child = _started.pop()
        try:
            os.killpg(child.pid, signal.SIGTERM)   # its own session: the warmup alone
            child.wait(timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            pass
        try:
            os.remove(stamp_path() + ".lock")
        except OSError:
            pass


def compile_kernels() -> float:
    """Run ``python -m taut._warmup`` and wait, unless the stamp is there: every kernel
    compiled into the cache and the stamp written (``taut compile``, the Makefile's
    install step); returns seconds (0 when already warm).

    Raises
    ------
    TautError
        numba is missing, disabled, or the warmup failed (its last line).
    """
    import subprocess

    if not _INSTALLED or MODE == "never":
        raise TautError("TAUT_NUMBA", not_compiled_reason())
    if is_warm():
        return 0.0
    _stop_own_warmup()
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "taut._warmup"], capture_output=True,
                         text=True, env=dict(os.environ, TAUT_NUMBA="always"))
    if run.returncode != 0:
        last = (run.stderr.strip().splitlines() or ["exit code " + str(run.returncode)])[-1]
        raise TautError("compile", last)
    return time.perf_counter() - t0


#: True when this process runs the compiled kernels (module docstring). A process that
#: imported numba before taut (a benchmark, a user's own jitted loop calling taut's
#: kernels, which plain Python functions would break) counts as ``always``.
HAVE_NUMBA = _INSTALLED and (MODE == "always" or (MODE == "auto" and (
    "numba" in sys.modules or is_warm())))
if MODE == "auto" and _INSTALLED and not HAVE_NUMBA:
    warm_in_background()


#: One-off cost (s) of loading the compiled kernels into a process: numba's import and
#: the cached machine code of the FK kernels, 0.4-0.6 s of CPU (bench/bench_startup.py).
LOAD_COST_S = 0.5
_numpy_seconds = [0.0]


def prefer_compiled() -> bool:
    """Whether a per-call front end (``forward_kinematics``) should use the compiled
    kernels now: when :data:`HAVE_NUMBA` and either numba is already loaded in this
    process or its numpy calls have taken :data:`LOAD_COST_S` in all (:func:`charge_numpy`).

    The rule of ski rental: a process making few calls never pays for loading, one
    making many pays at most twice what the better choice in hindsight would have cost.
    """
    return HAVE_NUMBA and ("numba" in sys.modules or _numpy_seconds[0] >= LOAD_COST_S)


def charge_numpy(seconds: float) -> None:
    """Add the duration of a numpy call made instead of a compiled one."""
    _numpy_seconds[0] += seconds


def not_compiled_reason() -> str:
    """Why :data:`HAVE_NUMBA` is False, for an error on ``backend="numba"``."""
    if not _INSTALLED:
        return "numba is not installed (pip install numba)"
    if MODE == "never":
        return "compiled kernels are disabled by TAUT_NUMBA=never"
    return ("the compiled kernels are not in the cache yet (they compile in the "
            "background; `taut compile` compiles them now, TAUT_NUMBA=always waits for "
            "the compiler)")


def jit(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit(cache=True)`` of ``fn`` when :data:`HAVE_NUMBA`, else ``fn`` itself."""
    return _njit(fn, "never")


def jit_inline(fn: Callable[..., Any]) -> Callable[..., Any]:
    """:func:`jit`, with ``fn`` inlined into every compiled caller (numba's
    ``inline="always"``, at numba's IR level) instead of called.

    For the small helpers a kernel calls per candidate or per row. A compiled call passes
    each array argument as ~7-9 machine words and LLVM does not inline these helpers on
    its own: on the 4-robot FK batch (bench/bench_fk.py's team, 3 rest states a formation)
    the calls were ~20 % of the kernel's time. The price is compile time (every caller
    compiles its own copy: ``taut compile`` ~67 s -> ~84 s of CPU), paid at install, not on
    a user's path. The results are the same floating-point operations (bit-identical
    rows, tests/sheet/fk). A caller's cache entry is not invalidated when an inlined
    helper in another file changes (as for any cross-file call; module docstring)."""
    return _njit(fn, "always")


def _njit(fn: Callable[..., Any], inline: Literal["never", "always"]) -> Callable[..., Any]:
    """``numba.njit`` of ``fn`` with the project's options when :data:`HAVE_NUMBA`, else
    ``fn`` itself."""
    if not HAVE_NUMBA:
        return fn
    import numba

    directory, override = cache_dir()
    if override:
        numba.config.CACHE_DIR = directory  # type: ignore[attr-defined]
    return numba.njit(cache=True, nogil=True, error_model="numpy", inline=inline)(fn)
