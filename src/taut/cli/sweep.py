"""`taut sweep SPEC --out DIR` runs a parameter study; `taut sweep plot DIR` draws it.

The sweep runs on a local Dask cluster by default (one worker process per CPU),
serially with ``--workers 0``, or on an existing cluster with ``--scheduler tcp://HOST:PORT``.
Results go to ``DIR/results.parquet``; ``--resume`` continues an interrupted run.
"""

from __future__ import annotations

import sys
import textwrap
import time
from pathlib import Path
from typing import Any, Optional

import typer
from typer.core import TyperGroup

from ..errors import InvalidInputError, SweepError
from ._paths import FIGURE_SUFFIXES, output_path
from ._progress import working

__all__ = ["register"]


class _DefaultRun(TyperGroup):
    """``taut sweep SPEC ...`` means ``taut sweep run SPEC ...``."""

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        if args and args[0] not in self.commands and not args[0].startswith("-"):
            args.insert(0, "run")
        return super().resolve_command(ctx, args)


#: Damaged chunks named one per line after a resumed run; past these, one line counts the
#: rest (a folder of a million damaged chunks prints a dozen lines).
DAMAGED_NAMED = 10

sweep_app = typer.Typer(cls=_DefaultRun, no_args_is_help=True, add_completion=False,
                        help="Parameter studies: `taut sweep SPEC --out DIR` runs one, "
                             "`taut sweep plot DIR --x P --value C` draws it.")


class _Reporter:
    """Progress on stderr: a rich bar on a terminal, else a line every few seconds."""

    def __init__(self) -> None:
        self.bar: Any = None
        self.task: Any = None
        self.last = 0.0
        if sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                       TimeRemainingColumn)
            self.bar = Progress(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(),
                                TextColumn("{task.fields[rate]} points/s"),
                                TimeRemainingColumn(), console=Console(stderr=True),
                                transient=True)

    def __enter__(self) -> "_Reporter":
        if self.bar is not None:
            self.bar.__enter__()
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.__exit__(*exc)

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        rate = done / max(now - self.t0, 1e-9)
        if self.bar is not None:
            if self.task is None:
                self.task = self.bar.add_task("sweep", total=total, rate="-")
            self.bar.update(self.task, completed=done, rate=f"{rate:.0f}")
            return
        if done < total and now - self.last < 5.0:
            return
        self.last = now
        eta = (total - done) / rate if rate > 0 else float("inf")
        print(f"taut: sweep: {done}/{total} points, {rate:.0f} points/s, ETA {eta:.0f} s",
              file=sys.stderr, flush=True)


@sweep_app.command("run", help="Run a sweep file and write DIR/results.parquet.")
def run_command(
    spec: Path = typer.Argument(..., help="Sweep file (YAML or JSON)."),
    out: Path = typer.Option(..., "--out", help="Results folder (created if missing)."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Worker processes of the "
                                          "local Dask cluster (default: one per CPU; 0 runs "
                                          "serially in this process)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Address of an "
                                            "existing Dask scheduler, tcp://HOST:PORT."),
    resume: bool = typer.Option(False, "--resume", help="Continue an earlier run of the same "
                                "sweep in DIR, skipping finished chunks."),
    limit: Optional[int] = typer.Option(None, "--limit", help="Only the first K points."),
) -> int:
    from ..sweep import load_sweep, run_sweep

    if workers is not None and workers < 0:
        raise InvalidInputError("--workers", f"must be >= 0, got {workers}")
    if limit is not None and limit < 1:
        raise InvalidInputError("--limit", f"must be >= 1, got {limit}")
    sweep = load_sweep(spec)
    with _Reporter() as report:
        result = run_sweep(sweep, out, workers=workers, scheduler=scheduler, resume=resume,
                           limit=limit, progress=report)
    if result.status == "interrupted" and result.message.startswith("interrupted"):
        raise KeyboardInterrupt             # Ctrl-C: the one line `taut: interrupted`
    _report_damaged(result.damaged, result.success)
    if not result.success:
        print(f"taut: sweep: {result.message}", file=sys.stderr)
        return 1
    print(f"{result.rows} rows -> {result.path} ({result.chunks_run} chunks computed, "
          f"{result.chunks_reused} reused, {result.seconds:.1f} s)")
    return 0


def _report_damaged(damaged: tuple[tuple[str, str], ...], done: bool) -> None:
    """Name on stderr the chunks found damaged in the folder (and so computed again)."""
    verb = "recomputed" if done else "found damaged, to recompute"
    for name, why in damaged[:DAMAGED_NAMED]:
        print(f"taut: sweep: chunks/{name} {verb} ({why})", file=sys.stderr)
    if len(damaged) > DAMAGED_NAMED:
        print(f"taut: sweep: and {len(damaged) - DAMAGED_NAMED} more damaged chunks {verb}",
              file=sys.stderr)


@sweep_app.command("plot", help="Draw a heat map (--x and --y) or a curve (--x only) of a "
                                "results column.")
def plot_command(
    folder: Path = typer.Argument(..., help="Results folder of `taut sweep`."),
    x: str = typer.Option(..., "--x", help="Parameter on the horizontal axis."),
    value: str = typer.Option(..., "--value", help="Column to draw (booleans become rates)."),
    y: Optional[str] = typer.Option(None, "--y", help="Parameter on the vertical axis."),
    out: Optional[Path] = typer.Option(None, "--out", help="Figure file (.png, .pdf, .svg; "
                                       "default DIR/<value>.png)."),
) -> int:
    from ..sweep import results_columns

    names, meta, _ = results_columns(folder)
    target = output_path(out if out is not None else folder / f"{value}.png", "--out",
                         FIGURE_SUFFIXES)
    assert target is not None
    for flag, name in (("--x", x), ("--y", y), ("--value", value)):
        if name is not None and name not in names:
            raise SweepError(flag, f"no column {name!r} in the results; columns: "
                             f"{', '.join(names)}")
    with working("sweep plot"):                  # a large sweep reads and draws for seconds
        _plot(folder, x, y, value, target, meta)
    print(f"figure -> {target}")
    return 0


def _plot(folder: Path, x: str, y: Optional[str], value: str, target: Path,
          meta: dict[str, str]) -> None:
    """Read the columns of a results folder and draw them (see :func:`plot_command`)."""
    from ..sweep import read_results

    columns, _ = read_results(folder, columns=[c for c in (x, y, value) if c is not None])
    from ..sweep import TASKS
    from ..viz.sweep import plot_sweep
    task = TASKS.get(meta.get("sweep_task", ""))
    described = {**task.parameters, **task.outputs} if task is not None else {}
    labels = {name: textwrap.fill(f"{name}: {text}", 48) for name, text in described.items()}
    title = f"{meta.get('sweep_task', 'sweep')}: {value}" + ("" if y is not None or
                                                             columns[value].dtype.kind != "b"
                                                             else " (rate)")
    plot_sweep(columns, x, value, target, y=y, title=title, labels=labels)


def register(app: typer.Typer) -> None:
    """Add ``taut sweep`` to the root command."""
    app.add_typer(sweep_app, name="sweep")
