"""Test helper: the ``taut`` command called in-process, and the bad-input promise.

``run`` calls :func:`taut.cli.main` with string arguments and returns ``(exit code, stdout,
stderr)``; ``one_line_error`` asserts a bad input's answer: exit 2, nothing on stdout and
one ``taut: error:`` line on stderr naming every word given.
"""

from __future__ import annotations

from taut.cli import main


def run(capsys, *args):
    """``(code, out, err)`` of ``taut *args`` run in this process."""
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, out, err, *words):
    """Exit 2, empty stdout, one error line on stderr containing every one of ``words``."""
    assert code == 2 and out == ""
    assert err.startswith("taut: error: ") and err.count("\n") == 1, err
    for w in words:
        assert w in err, err
