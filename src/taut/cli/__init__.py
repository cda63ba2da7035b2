"""The ``taut`` command.

Each subcommand family lives in its own module exposing ``register(app)``. :func:`main`
turns every user mistake (a :class:`taut.errors.TautError` or a command-line usage error)
into one line on stderr and exit code 2; nothing a user types produces a traceback.

Exit codes (the same in every command):

====  =====================================================================================
0     the question was answered "yes" (a plan, a placement, equilibria, feasible tensions)
1     a valid question answered "no" (no equilibrium, tensions infeasible, target
      unreachable, no plan, no placement); the reason is printed
2     invalid input: one line ``taut: error: <field>: <problem>`` on stderr
====  =====================================================================================

``taut <command>`` imports only that command's module (:data:`COMMANDS`), and commands
import their solvers when they run, so ``taut --help`` loads no scipy and ``taut fk`` no
planner, cable-robot model or matplotlib (tests/cli/test_startup.py).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import warnings
from collections.abc import Iterable
from functools import lru_cache
from importlib import import_module
from typing import Any

import typer
from typer.exceptions import TyperException

from .. import __version__
from ..errors import EXTRAS, MissingExtraError, TautError
from ._progress import computing

#: The root command's settings.
_APP_OPTIONS: dict[str, Any] = dict(
    name="taut",
    help="Carrying loads with cables and mobile robots. Exit codes: 0 answered yes; 1 a "
         "valid question answered no (no equilibrium, infeasible tensions, unreachable "
         "target, no plan or placement), with the reason; 2 invalid input, with one line "
         "'taut: error: <field>: <problem>' on stderr.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

#: Each top-level command -> the module of this package that registers it. ``taut <command>``
#: imports only that module (and what the command itself needs); help and an unknown
#: command load them all.
COMMANDS = {"fk": "fk", "ik": "motion", "simulate": "motion", "plan": "plan",
            "cdpr": "cdpr", "physics": "physics", "sweep": "sweep", "app": "webapp",
            "compile": "warmup"}


def build_app(commands: Iterable[str] = tuple(COMMANDS)) -> typer.Typer:
    """The ``taut`` Typer app with the given top-level ``commands`` (keys of
    :data:`COMMANDS`); ``app``, this module's attribute, is the app with all of them."""
    app = typer.Typer(**_APP_OPTIONS)
    app.callback()(_root)
    for name in dict.fromkeys(COMMANDS[c] for c in commands):
        import_module(f"{__name__}.{name}").register(app)
    return app


@lru_cache(maxsize=None)
def _command(commands: tuple[str, ...]) -> Any:
    """The click command of ``build_app(commands)``, built once per process for each set
    of commands. Typer converts its whole app into click objects on every call of the app
    (1-20 ms by the command); a process calling :func:`main` many times (the test suite,
    a script looping over command lines) paid that per call. click makes a fresh context
    for every invocation, so nothing carries over from one call to the next."""
    return typer.main.get_command(build_app(commands))


def __getattr__(name: str) -> Any:
    if name == "app":
        return build_app()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _needed(args: list[str]) -> tuple[str, ...]:
    """The commands a command line needs registered: the one it names (its first word
    that is not an option), none for ``--version``, all for help or an unknown name."""
    command = next((a for a in args if not a.startswith("-")), None)
    if command in COMMANDS:
        return (command,)
    return () if command is None and "--version" in args else tuple(COMMANDS)


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"taut {__version__}")
        raise typer.Exit()


def _root(version: bool = typer.Option(False, "--version", callback=_print_version,
                                       is_eager=True, help="Print the version and exit.")
          ) -> None:
    """Carrying loads with cables and mobile robots: sheet-carrying robot teams (VVCM) and
    cable-driven parallel robots on mobile bases.

    Exit codes: 0 answered yes; 1 a valid question answered no (no equilibrium,
    infeasible tensions, unreachable target, no plan or placement); 2 invalid input, with
    one line ``taut: error: <field>: <problem>`` on stderr."""


EXIT_NO = 1
EXIT_USAGE = 2
#: Exit code after Ctrl-C (128 + SIGINT, the shell's convention).
EXIT_INTERRUPTED = 130

#: Set by the Ctrl-C handler: checked when the command returns, so an interrupt that
#: library code swallowed (numba turns it into a SystemError inside a kernel call) still
#: ends the command as interrupted.
_interrupt = threading.Event()


#: After a Ctrl-C, the interrupt is raised again this often (s) while the command computes
#: (inside :func:`taut.cli._progress.working`) until it has stopped: a library may swallow
#: a KeyboardInterrupt (pyarrow's lazy import of pandas does, so `taut sweep plot` drew and
#: wrote its figure for 4 s after Ctrl-C).
REPEAT_INTERRUPT_S = 0.25
#: Set once the interrupt has been raised (it may have been swallowed since).
_raised = threading.Event()


def _on_sigint(signum: int, frame: Any) -> None:
    """First Ctrl-C: note it and raise KeyboardInterrupt at the next Python step (between
    kernel calls); a second one: leave at once.

    Python ignores (prints and drops) an exception raised inside a finalizer or a ctypes
    callback, which numba and llvmlite run while compiling (llvmlite's object-cache
    notification is a ctypes callback); there the interrupt is raised again 50 ms later
    (SIGALRM), outside it. After that it is raised again every ``REPEAT_INTERRUPT_S`` while
    the command computes, unless an exception is being handled (cleanup on the way out:
    ``finally`` blocks, context managers) or the interrupt was reported."""
    if signum == signal.SIGINT:
        if _interrupt.is_set():
            os.write(2, b"taut: interrupted\n")
            os._exit(EXIT_INTERRUPTED)
        _interrupt.set()
        if hasattr(signal, "setitimer"):
            signal.setitimer(signal.ITIMER_REAL, 0.05, REPEAT_INTERRUPT_S)
    elif (_reported.is_set() or sys.exc_info()[0] is not None
          or (_raised.is_set() and not computing())):
        return
    depth = 0
    while frame is not None and depth < 64:
        code = frame.f_code
        if code.co_name == "__del__" or "llvmlite" in code.co_filename:
            return                                   # the timer raises it again
        frame, depth = frame.f_back, depth + 1
    _raised.set()
    raise KeyboardInterrupt


def _interrupted(exc: BaseException | None) -> bool:
    """Whether a KeyboardInterrupt is in the exception's cause/context chain."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def _missing_extra(exc: ModuleNotFoundError) -> str | None:
    """The one line for an optional dependency that is not installed, else None."""
    top = (exc.name or "").split(".")[0]
    return str(MissingExtraError(top)) if top in EXTRAS else None


#: Set once ``taut: interrupted`` is printed: an interrupt reaches several handlers (the
#: command's, typer's ``Exit(130)``, :func:`main`'s check of ``_interrupt``) and is
#: reported once.
_reported = threading.Event()


def _stopped() -> int:
    if not _reported.is_set():
        _reported.set()
        try:
            print("taut: interrupted", file=sys.stderr)
        except (OSError, ValueError):
            pass
    return EXIT_INTERRUPTED


def _fail(message: str) -> int:
    print(f"taut: error: {message}", file=sys.stderr)
    return EXIT_USAGE


def _usage_line(exc: Exception) -> str:
    """One line for a command-line usage error (typer's click exceptions)."""
    option = getattr(exc, "option_name", None)
    if option and type(exc).__name__ == "NoSuchOption":
        return f"{option}: no such option"
    if option:                                 # e.g. "Option '--pose' requires 3 arguments."
        text = " ".join(str(getattr(exc, "message", exc)).split())
        text = text.replace(f"Option '{option}' ", "").rstrip(".")
        return f"{option}: {text}"
    param = getattr(exc, "param", None)
    name = None
    if param is not None:
        opts = getattr(param, "opts", None) or []
        name = opts[0] if opts and opts[0].startswith("-") else getattr(param, "name", None)
    message = getattr(exc, "message", None) or str(exc)
    if type(exc).__name__ == "MissingParameter":
        message = "missing"
    message = " ".join(message.split())
    return f"{name}: {message}" if name else message


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the process exit code (0 yes, 1 a valid question answered no,
    2 bad input).

    Numeric warnings of numpy (overflow, invalid values) never reach the terminal: inputs
    are range-checked before any solver runs (:mod:`taut._validate`), and what remains
    inside a solver is its own business (it reports NaN/None, never a silent wrong answer).

    Ctrl-C ends any command with exit code 130 and the one line ``taut: interrupted``
    (whatever was running: a numba kernel's interrupt surfaces between kernel calls);
    files a command writes are written whole or not at all.
    """
    _interrupt.clear()
    _reported.clear()
    _raised.clear()
    from ._paths import set_command_line
    set_command_line(sys.argv[1:] if argv is None else list(argv))
    installed = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, _on_sigint) if installed else None
    alarm = (signal.signal(signal.SIGALRM, _on_sigint)
             if installed and hasattr(signal, "SIGALRM") else None)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            import numpy as np
            with np.errstate(all="ignore"):
                code = _run(argv)
        return _stopped() if _interrupt.is_set() else code
    except KeyboardInterrupt:
        return _stopped()
    finally:
        if installed:
            signal.signal(signal.SIGINT, previous)
            if alarm is not None:               # no deferred interrupt may outlive us
                signal.setitimer(signal.ITIMER_REAL, 0)
                signal.signal(signal.SIGALRM, alarm)


def _run(argv: list[str] | None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    try:
        result = _command(_needed(args)).main(args=args, prog_name="taut",
                                              standalone_mode=False)
    except TautError as exc:
        return _fail(str(exc))
    except KeyboardInterrupt:
        return _stopped()
    except typer.Abort as exc:
        return _stopped() if _interrupted(exc) else _fail("aborted")
    except typer.Exit as exc:
        return int(getattr(exc, "exit_code", 0) or 0)
    except TyperException as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":
            try:
                print(exc.format_message() if hasattr(exc, "format_message") else exc)
            except BrokenPipeError:
                pass
            return 0
        return _fail(_usage_line(exc))
    except BrokenPipeError:
        return 0
    except OSError as exc:                       # e.g. the disk filled up while writing
        where = exc.filename if isinstance(exc.filename, str) else "file"
        return _fail(f"{where}: {exc.strerror or exc}")
    except MemoryError:
        return _fail("input: too large to fit in memory")
    except ModuleNotFoundError as exc:           # an optional extra that is not installed
        line = _missing_extra(exc)
        if line is None:
            raise
        return _fail(line)
    except SystemError as exc:                   # numba: a kernel interrupted by Ctrl-C
        if _interrupted(exc) or _interrupt.is_set():
            return _stopped()
        raise
    return int(result) if isinstance(result, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
