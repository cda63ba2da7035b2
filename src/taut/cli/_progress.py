"""Progress on stderr for commands that can run longer than about two seconds.

On a terminal: a transient rich spinner with the elapsed time (or a bar when the analysis
reports steps). Elsewhere (pipes, CI logs): one plain line when the work has taken 2 s and
then one every 10 s, so a long run is never silent and a short one prints nothing.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["working", "FIRST_NOTICE_S", "NOTICE_EVERY_S"]

#: A run shorter than this prints no progress at all, s.
FIRST_NOTICE_S = 2.0
#: Interval between the plain progress lines when stderr is not a terminal, s.
NOTICE_EVERY_S = 10.0


def _plain(label: str, stop: threading.Event, state: dict[str, str]) -> None:
    start = time.monotonic()
    wait = FIRST_NOTICE_S
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
    stop = threading.Event()

    def update_plain(done: int, total: int) -> None:
        state["detail"] = f"{done}/{total}"

    thread = threading.Thread(target=_plain, args=(label, stop, state), daemon=True)
    thread.start()
    try:
        yield update_plain
    finally:
        stop.set()
        thread.join()
