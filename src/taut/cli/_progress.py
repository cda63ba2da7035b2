"""Progress on stderr for commands that can run longer than about two seconds.

On a terminal: a transient rich spinner with the elapsed time (or a bar when the analysis
reports steps). Elsewhere (pipes, CI logs): one plain line when the work has taken 2 s and
then one every 10 s, so a long run is never silent and a short one prints nothing. The
environment variable ``TAUT_PROGRESS_AFTER_S`` sets when the first line comes (s; e.g. 0
for a log that should show every run).
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["working", "computing", "FIRST_NOTICE_S", "NOTICE_EVERY_S", "first_notice_s"]

#: A run shorter than this prints no progress at all, s (default of
#: ``TAUT_PROGRESS_AFTER_S``).
FIRST_NOTICE_S = 2.0
#: Largest ``TAUT_PROGRESS_AFTER_S``, s (a day; a longer wait overflows the thread's timer).
MAX_FIRST_NOTICE_S = 86_400.0
#: Interval between the plain progress lines when stderr is not a terminal, s.
NOTICE_EVERY_S = 10.0


#: How many :func:`working` blocks are open (the main thread's command computing).
_open = [0]


def computing() -> bool:
    """Whether a command is inside :func:`working` (its computation, where a swallowed
    Ctrl-C is raised again: :func:`taut.cli._on_sigint`)."""
    return _open[0] > 0


def first_notice_s() -> float:
    """Seconds before the first plain progress line: ``TAUT_PROGRESS_AFTER_S`` from the
    environment (a finite number >= 0) or :data:`FIRST_NOTICE_S`."""
    from ..errors import InvalidInputError

    raw = os.environ.get("TAUT_PROGRESS_AFTER_S", "").strip()
    if not raw:
        return FIRST_NOTICE_S
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0 <= value <= MAX_FIRST_NOTICE_S):
        raise InvalidInputError("TAUT_PROGRESS_AFTER_S", f"must be a number of seconds in "
                                f"0..{MAX_FIRST_NOTICE_S:g}, got {raw!r}")
    return value


def _plain(label: str, stop: threading.Event, state: dict[str, str], first: float) -> None:
    start = time.monotonic()
    wait = first
    while not stop.wait(wait):
        detail = state.get("detail", "")
        print(f"taut: {label}: working, {time.monotonic() - start:.0f} s"
              + (f" ({detail})" if detail else ""), file=sys.stderr, flush=True)
        wait = NOTICE_EVERY_S


@contextmanager
def working(label: str) -> Iterator[Callable[[int, int], None]]:
    """Show that ``label`` is running; yields ``update(done, total)`` for analyses that
    report their steps (it may be ignored).

    Examples
    --------
    >>> with working("demo") as update:
    ...     update(1, 2)
    """
    _open[0] += 1
    try:
        with _shown(label) as update:
            yield update
    finally:
        _open[0] -= 1


@contextmanager
def _shown(label: str) -> Iterator[Callable[[int, int], None]]:
    """The spinner or the plain lines of :func:`working`."""
    state: dict[str, str] = {}
    if sys.stderr.isatty():
        from rich.progress import (BarColumn, Progress, SpinnerColumn, TextColumn,
                                   TimeElapsedColumn)
        with Progress(SpinnerColumn(), TextColumn(label), BarColumn(),
                      TimeElapsedColumn(), transient=True) as bar:
            task = bar.add_task(label, total=None)

            def update(done: int, total: int) -> None:
                bar.update(task, completed=done, total=total)

            yield update
        return
    first = first_notice_s()
    stop = threading.Event()

    def update_plain(done: int, total: int) -> None:
        state["detail"] = f"{done}/{total}"

    thread = threading.Thread(target=_plain, args=(label, stop, state, first), daemon=True)
    thread.start()
    try:
        yield update_plain
    finally:
        stop.set()
        thread.join()
