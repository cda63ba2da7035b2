"""The ``taut`` command.

Each subcommand family lives in its own module exposing ``register(app)``. :func:`main`
turns every user mistake (a :class:`taut.errors.TautError` or a command-line usage error)
into one line on stderr and exit code 2; nothing a user types produces a traceback.
"""

from __future__ import annotations

import sys

import click
import typer

from ..errors import TautError
from . import cdpr, fk, motion

app = typer.Typer(
    name="taut",
    help="Carrying loads with cables and mobile robots.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

for _module in (fk, motion, cdpr):
    _module.register(app)

EXIT_USAGE = 2


def _fail(message: str) -> int:
    print(f"taut: error: {message}", file=sys.stderr)
    return EXIT_USAGE


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the process exit code (0 success, 2 bad input)."""
    try:
        result = app(args=argv, prog_name="taut", standalone_mode=False)
    except TautError as exc:
        return _fail(str(exc))
    except click.exceptions.NoSuchOption as exc:
        return _fail(f"{exc.option_name}: no such option")
    except click.exceptions.BadParameter as exc:
        name = exc.param.name if exc.param is not None else "argument"
        return _fail(f"{name}: {exc.message}")
    except click.exceptions.MissingParameter as exc:
        name = exc.param.name if exc.param is not None else "argument"
        return _fail(f"{name}: missing")
    except click.exceptions.UsageError as exc:
        return _fail(exc.format_message().splitlines()[0])
    except click.exceptions.Abort:
        return _fail("aborted")
    except BrokenPipeError:
        return 0
    return int(result) if isinstance(result, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
