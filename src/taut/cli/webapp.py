"""`taut app`: serve the interactive explorer on localhost (needs the ``app`` extra)."""

from __future__ import annotations

import os
import sys
import threading
import webbrowser
from pathlib import Path
from typing import Optional

import typer

from ..errors import InvalidInputError

__all__ = ["register"]


def _validated(path: Path) -> dict:
    """Read and validate SCENARIO with the loader of its kind, before serving."""
    from ..app.payload import kind_of_mapping
    from ..io import (cdpr_model_from_mapping, plan_scenario_from_mapping, read_mapping,
                      sheet_scenario_from_mapping)

    data = read_mapping(path)          # size limit and alias bombs refused here
    load = {"sheet": sheet_scenario_from_mapping, "plan": plan_scenario_from_mapping,
            "cdpr": cdpr_model_from_mapping}[kind_of_mapping(data)]
    load(data)
    return data


def app_command(
    scenario: Optional[Path] = typer.Argument(None, help="Sheet scenario, planning "
                                              "scenario or cable-robot model file to open."),
    port: int = typer.Option(8765, "--port", help="TCP port (0: any free port)."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on "
                             "(default: this machine only)."),
    open_browser: bool = typer.Option(False, "--open", help="Open the page in a browser."),
) -> int:
    """Serve an interactive web app: drag robots and watch the object, run and replay
    plans, move a cable robot's platform. The URL printed carries a per-launch secret
    token; requests without it are refused. Stop with Ctrl+C."""
    if not 0 <= port <= 65535:
        raise InvalidInputError("--port", f"must be between 0 and 65535, got {port}")
    from ..app.server import bind, create_app, serve   # a MissingExtraError without the extra
    initial = _validated(scenario) if scenario is not None else None
    app = create_app(initial, hosts=(host,))
    sock = bind(host, port)
    bound = sock.getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    url = f"http://{shown}:{bound}/?token={app.state.token}"
    typer.echo(f"taut app: serving on {url}  (Ctrl+C to stop)")
    if open_browser:
        webbrowser.open(url)
    try:
        serve(sock, app)
    except KeyboardInterrupt:
        pass
    finally:
        sock.close()
    if any(t.is_alive() and not t.daemon for t in threading.enumerate()
           if t is not threading.main_thread()):
        # A request or planning job still computing (numerical code cannot be stopped
        # midway): leave now rather than wait for it after the user pressed Ctrl+C.
        sys.stdout.flush()
        print("taut: interrupted", file=sys.stderr, flush=True)
        os._exit(130)
    return 0


def register(app: typer.Typer) -> None:
    """Add ``taut app``."""
    app.command("app")(app_command)
