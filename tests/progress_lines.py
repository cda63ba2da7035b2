"""Test helper: stderr without the CLI's progress notices.

A command that runs longer than ``taut.cli._progress.FIRST_NOTICE_S`` (a loaded machine)
prints ``taut: <label>: working, N s`` lines on stderr; tests that promise a silent
stderr check what remains once those are removed, so they do not depend on the load.
"""

from __future__ import annotations

import re

_NOTICE = re.compile(r"^taut: [^:\n]+: working, \d+ s.*\n?", re.M)


def without_progress(err: str) -> str:
    """``err`` with every progress notice line removed."""
    return _NOTICE.sub("", err)
