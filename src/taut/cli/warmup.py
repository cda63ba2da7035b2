"""`taut compile`: compile the numba kernels now (docs/compiled_kernels.md)."""

from __future__ import annotations

import typer


def register(app: typer.Typer) -> None:
    """Add ``taut compile``."""

    @app.command("compile")
    def compile_command() -> int:
        """Compile taut's numba kernels into the cache now and wait for it (a minute or
        two; nothing to do when they are there), so that every later command runs compiled
        code. Without it, the first command answers with the numpy engines and starts
        this in the background."""
        from .._jit import compile_kernels

        seconds = compile_kernels()
        typer.echo("taut: compiled kernels " + (f"ready in {seconds:.1f} s" if seconds
                                                 else "already in the cache"))
        return 0
