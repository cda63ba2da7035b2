"""The ASGI application behind ``taut app`` and the function that serves it.

Routes: ``GET /`` (the page), ``/static/*`` (its scripts), ``GET /api/catalog`` (bundled
scenarios), ``GET /api/initial`` (the scenario given on the command line), ``POST
/api/<view>/<action>`` for the views' endpoints (:mod:`.sheet_api`, :mod:`.plan_api`,
:mod:`.cdpr_api`), ``GET /api/plan/job/<id>``.

Every reply is JSON. Bad input gives HTTP 422 and ``{"error": "<field>: <problem>"}`` (the
line the CLI prints); anything unexpected gives HTTP 500 with a one-line ``error`` and is
logged with its traceback on the server's stderr only, never sent to the page.
"""

from __future__ import annotations

import contextlib
import json
import logging
import socket
from collections.abc import AsyncIterator, Callable
from importlib import resources
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import BaseRoute, Mount, Route
from starlette.staticfiles import StaticFiles

from ..errors import InvalidInputError, TautError
from ..io.serialize import json_ready
from .catalog import Catalog
from .cdpr_api import CdprAPI
from .payload import kind_of_mapping
from .plan_api import PlanAPI
from .sheet_api import SheetAPI

__all__ = ["create_app", "bind", "serve", "static_dir"]

log = logging.getLogger("taut.app")

#: Largest request body accepted (an uploaded scenario or a long drag path), bytes.
MAX_BODY = 8 * 1024 * 1024


def static_dir() -> Path:
    """Folder of the page's HTML, CSS and JavaScript (package data)."""
    return Path(str(resources.files("taut.app") / "static"))


class _JSON(JSONResponse):
    """JSON without NaN (the page's JSON.parse rejects it): NaN/inf become null."""

    def render(self, content: Any) -> bytes:
        return json.dumps(json_ready(content), allow_nan=False,
                          separators=(",", ":")).encode("utf-8")


def _endpoint(handler: Callable[[dict[str, Any]], dict[str, Any]]):
    """Wrap a ``body -> dict`` handler as a POST route with the error contract above."""

    async def route(request: Request) -> Response:
        try:
            raw = await request.body()
            if len(raw) > MAX_BODY:
                raise InvalidInputError("request", f"larger than {MAX_BODY // 2**20} MiB")
            try:
                body = json.loads(raw or b"{}")
            except (ValueError, UnicodeDecodeError):
                raise InvalidInputError("request", "is not valid JSON") from None
            if not isinstance(body, dict):
                raise InvalidInputError("request", "must be a JSON object")
            return _JSON(handler(body))
        except TautError as exc:
            return _JSON({"error": str(exc)}, status_code=422)
        except Exception as exc:               # a bug: log it here, one line to the page
            log.exception("internal error in %s", request.url.path)
            return _JSON({"error": f"internal error ({exc.__class__.__name__}); the "
                                   "server log has the details"}, status_code=500)
    return route


def create_app(initial: dict[str, Any] | None = None, *,
               catalog: Catalog | None = None) -> Starlette:
    """The Starlette application.

    Parameters
    ----------
    initial : dict, optional
        A scenario mapping to open first (from ``taut app SCENARIO``); its view is
        chosen by its keys (:func:`taut.app.payload.kind_of_mapping`).
    catalog : Catalog, optional
        Where bundled examples come from (default: the source checkout's ``examples/``).
    """
    catalog = catalog or Catalog()
    sheet, planner, cdpr = SheetAPI(catalog), PlanAPI(catalog), CdprAPI(catalog)
    start = None if initial is None else {"kind": kind_of_mapping(initial), "mapping": initial}
    page = static_dir() / "index.html"

    async def index(request: Request) -> Response:
        return FileResponse(page, headers={"Cache-Control": "no-store"})

    async def get_catalog(request: Request) -> Response:
        return _JSON(catalog.names())

    async def get_initial(request: Request) -> Response:
        return _JSON({"initial": start})

    async def get_job(request: Request) -> Response:
        return await _endpoint(lambda _: planner.job(request.path_params["jid"]))(request)

    routes: list[BaseRoute] = [Route("/", index), Route("/api/catalog", get_catalog),
              Route("/api/initial", get_initial),
              Route("/api/plan/job/{jid}", get_job)]
    for view, api, actions in (("sheet", sheet, ("load", "fk", "ik", "simulate", "yaml")),
                               ("plan", planner, ("load", "run", "yaml")),
                               ("cdpr", cdpr, ("load", "state", "workspace", "yaml"))):
        for action in actions:
            routes.append(Route(f"/api/{view}/{action}", _endpoint(getattr(api, action)),
                                methods=["POST"]))
    routes.append(Mount("/static", StaticFiles(directory=str(static_dir())), name="static"))

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        yield
        planner.close()

    return Starlette(routes=routes, lifespan=lifespan)


def bind(host: str, port: int) -> socket.socket:
    """A listening TCP socket on ``host:port`` (port 0: any free port).

    Raises
    ------
    InvalidInputError
        ``--port``: the port is in use or cannot be bound; ``--host``: unknown address.
    """
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror:
        raise InvalidInputError("--host", f"cannot resolve {host!r}") from None
    family, kind, proto, _, addr = infos[0]
    # proto must be IPPROTO_TCP: asyncio sets TCP_NODELAY on accepted connections only
    # then, and without it a reply split in two segments waits ~40 ms for a delayed ACK.
    sock = socket.socket(family, kind, proto or socket.IPPROTO_TCP)
    try:
        sock.bind(addr)
        sock.listen(128)
    except OSError as exc:
        sock.close()
        if exc.errno in (98, 48, 10048):        # EADDRINUSE on Linux, macOS, Windows
            raise InvalidInputError("--port", f"port {port} on {host} is already in use; "
                                              "choose another with --port") from None
        raise InvalidInputError("--port", f"cannot listen on {host}:{port} "
                                          f"({exc.strerror or exc})") from None
    return sock


def serve(sock: socket.socket, app: Starlette, *, log_level: str = "warning") -> None:
    """Serve ``app`` on an already bound socket until interrupted (uvicorn)."""
    import uvicorn

    config = uvicorn.Config(app, log_level=log_level, access_log=False, lifespan="on")
    uvicorn.Server(config).run(sockets=[sock])
