"""Output paths of the `taut` commands, checked before any work starts.

Every ``--plot``, ``--animate``, ``--out`` (and any other file the CLI writes) goes through
:func:`output_path`, so a mistake in a path costs the user one line and exit code 2 instead
of a finished computation followed by a traceback, and an output that is (or resolves to,
through ``..``, a symbolic or a hard link) one of the command's input files is refused
before any work: ``taut plan sc.json --out sc.json`` would otherwise replace the scenario
with the plan. The command's files are the existing files named on its command line
(:func:`set_command_line`, called by :func:`taut.cli.main`); files are compared by device
and inode, so two spellings of one file are one file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ..errors import InvalidInputError

__all__ = ["output_path", "set_command_line", "FIGURE_SUFFIXES", "ANIMATION_SUFFIXES",
           "JSON_SUFFIXES"]

#: Formats matplotlib writes with its default (Agg) backends.
FIGURE_SUFFIXES = (".png", ".pdf", ".svg")
#: Animated figures (Pillow writer).
ANIMATION_SUFFIXES = (".gif",)
#: Machine-readable output files.
JSON_SUFFIXES = (".json",)

#: The words of the running command's line (set by :func:`set_command_line`).
_ARGV: list[str] = []
#: The outputs this command line has claimed so far: resolved path -> option.
_CLAIMED: dict[str, str] = {}


def set_command_line(argv: list[str]) -> None:
    """Remember the command line whose files :func:`output_path` protects."""
    _ARGV[:] = [str(a) for a in argv]
    _CLAIMED.clear()


def _identity(text: str) -> tuple[int, int] | None:
    """(device, inode) of an existing regular file, else None."""
    try:
        st = os.stat(text)
    except (OSError, ValueError):
        return None
    return (st.st_dev, st.st_ino) if stat.S_ISREG(st.st_mode) else None


def _named_files() -> list[tuple[int, int]]:
    """Identities of the existing files named on the command line (``--opt=FILE`` too)."""
    out = []
    for word in _ARGV:
        for text in {word, word.split("=", 1)[-1]} if word.startswith("-") else {word}:
            ident = _identity(text)
            if ident is not None:
                out.append(ident)
    return out


def output_path(value: str | os.PathLike[str] | None, field: str,
                suffixes: tuple[str, ...]) -> Path | None:
    """Validate a file the command will write; ``None`` passes through.

    Parameters
    ----------
    value : path or None
        What the user typed.
    field : str
        The option name used in the error (``"--plot"``).
    suffixes : tuple of str
        Accepted extensions, lower case with the dot (``(".png", ".pdf")``).

    Returns
    -------
    Path or None
        The path, unchanged (the file is written exactly where the user asked).

    Raises
    ------
    InvalidInputError
        An empty name, a name without or with an unsupported extension, an existing
        directory, a parent that is not a directory, a directory that is not writable,
        a file that is also one of the command's inputs, or a file another option of the
        command already writes.

    Examples
    --------
    >>> output_path("fig.png", "--plot", (".png",))
    PosixPath('fig.png')
    >>> output_path("fig", "--plot", (".png", ".pdf"))
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: --plot: 'fig' has no file extension; use one of .png, .pdf
    """
    if value is None:
        return None
    text = os.fspath(value)
    want = ", ".join(suffixes)
    if text.strip() == "":
        raise InvalidInputError(field, f"empty file name; give a file ending in {want}")
    path = Path(text)
    if text.strip() == ".":                 # typer turns an empty argument into "."
        raise InvalidInputError(field, f"empty file name; give a file ending in {want}")
    if path.is_dir() or text.endswith(("/", os.sep)):
        raise InvalidInputError(field, f"{text!r} is a directory; give a file ending in {want}")
    suffix = path.suffix.lower()
    if not suffix or path.name.startswith(".") and path.name.count(".") == 1:
        raise InvalidInputError(field, f"{text!r} has no file extension; use one of {want}")
    if suffix not in suffixes:
        raise InvalidInputError(field, f"unsupported extension {path.suffix!r}; use one "
                                       f"of {want}")
    ancestor = path.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise InvalidInputError(field, f"{str(ancestor)!r} is not a directory")
    if path.exists() and not os.access(path, os.W_OK):
        raise InvalidInputError(field, f"{text!r} exists and is not writable")
    ident = _identity(text)
    if ident is not None and _named_files().count(ident) > 1:
        raise InvalidInputError(field, f"{text!r} is also an input of this command; "
                                       "writing it would destroy that input (choose "
                                       "another file)")
    key = os.path.realpath(text)
    other = _CLAIMED.setdefault(key, field)
    if other != field:
        raise InvalidInputError(field, f"{text!r} is also the file of {other}; give each "
                                       "output its own file")
    _probe(path, field)
    return path


def _probe(path: Path, field: str) -> None:
    """Create the parent directories and open the file for appending (removing it again if
    it did not exist): the only test that holds on every file system (``os.access`` says
    yes to root on read-only mounts and on ``/proc``)."""
    existed = path.exists()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "ab"):
            pass
    except OSError as exc:
        where = exc.filename if isinstance(exc.filename, str) else str(path)
        raise InvalidInputError(field, f"cannot write {where!r} ({exc.strerror or exc})"
                                ) from None
    if not existed:
        path.unlink(missing_ok=True)
