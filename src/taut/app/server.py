"""The ASGI application behind ``taut app`` and the function that serves it.

Routes: ``GET /`` (the page), ``/static/*`` (its scripts), ``GET /api/catalog`` (bundled
scenarios), ``GET /api/initial`` (the scenario given on the command line), ``POST
/api/<view>/<action>`` for the views' endpoints (:mod:`.sheet_api`, :mod:`.plan_api`,
:mod:`.cdpr_api`), ``GET /api/plan/job/<id>``.

Only its user can drive it (the model of JupyterLab's and the Dask dashboard's servers):

* every ``/api/`` request carries the per-launch secret token (``X-Taut-Token`` header or
  ``?token=`` query; the page reads it from the URL ``taut app`` prints), else HTTP 403;
* the ``Host`` header must name this machine (``127.0.0.1``, ``localhost``, ``::1`` or the
  address served on), which defeats DNS rebinding, and a request with an ``Origin``
  header must come from the page itself (same scheme, host and port), else HTTP 403;
* a POST must say ``Content-Type: application/json`` (a cross-site form or a
  ``text/plain`` fetch cannot), else HTTP 415; no CORS headers are ever sent;
* a body is counted while it streams in: past :data:`MAX_BODY` bytes HTTP 413 (before the
  rest is read), slower than :data:`BODY_TIMEOUT_S` HTTP 408;
* the views' requests are computed by worker processes (:mod:`.pool`, one per core, at
  most :data:`taut.app.pool.MAX_WORKERS`):
  the raw body goes to a worker, which parses it, computes and renders the reply, so the
  event loop only moves bytes and the page, its scripts, the catalog and job polls
  answer while heavy requests run; a request is cancelled by killing its worker when the
  client disconnects, when it overruns its time budget (``budget_s``, HTTP 503) and on
  Ctrl-C; a worker's address space is capped (:data:`taut.app.worker.MEMORY_LIMIT`; a
  request needing more gets HTTP 507);
* planning jobs are queued (:mod:`.jobs`: at most ``max_jobs``, HTTP 503 "busy" past
  that; an id stays valid until its finished result has been fetched).

Every reply is JSON, errors included: ``{"error": "<field>: <problem>"}`` (the line the
CLI prints) with HTTP 422 for bad input, 403/404/405/408/413/415/503/507 as above, and HTTP 500
with a one-line ``error`` for a bug, logged with its traceback on the server's stderr
only, never sent to the page.
"""

from __future__ import annotations

import contextlib
import hmac
import secrets
import socket
from collections.abc import AsyncIterator, Awaitable, Callable
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from ..errors import InvalidInputError, MissingExtraError

try:
    import anyio
    from starlette.applications import Starlette
    from starlette.exceptions import HTTPException
    from starlette.requests import Request
    from starlette.responses import FileResponse, JSONResponse, Response
    from starlette.routing import BaseRoute, Mount, Route
    from starlette.staticfiles import StaticFiles
    from starlette.types import ASGIApp, Receive, Scope, Send
except ImportError as exc:                  # the app extra is missing: one line naming it
    raise MissingExtraError(exc.name or "starlette") from None

from .catalog import Catalog
from .jobs import PlanJobs
from .payload import kind_of_mapping
from .pool import WorkerPool, default_size
from .worker import render

__all__ = ["create_app", "bind", "serve", "static_dir", "new_token", "LOOPBACK_HOSTS"]

#: Largest request body accepted (an uploaded scenario or a long drag path), bytes.
MAX_BODY = 8 * 1024 * 1024
#: Longest wait for a request body to arrive in full, s.
BODY_TIMEOUT_S = 10.0
#: Default time budget of one request's work, s.
BUDGET_S = 60.0
#: Longest wait after Ctrl-C for replies in progress before the app stops, s (uvicorn
#: takes whole seconds).
SHUTDOWN_S = 1
#: Header that carries the token.
TOKEN_HEADER = "x-taut-token"
#: Host names that always mean this machine.
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "::1")


def static_dir() -> Path:
    """Folder of the page's HTML, CSS and JavaScript (package data)."""
    return Path(str(resources.files("taut.app") / "static"))


def new_token() -> str:
    """A fresh per-launch secret (43 URL-safe characters, 256 bits)."""
    return secrets.token_urlsafe(32)


class _JSON(JSONResponse):
    """JSON without NaN (the page's JSON.parse rejects it): NaN/inf become null."""

    def render(self, content: Any) -> bytes:
        return render(content)


def _error(status: int, line: str) -> Response:
    return _JSON({"error": line}, status_code=status)


class _Refused(Exception):
    """A request refused before its handler runs (status and one line)."""

    def __init__(self, status: int, line: str) -> None:
        super().__init__(line)
        self.status, self.line = status, line


def _host_name(host: str) -> str:
    """``"[::1]:8765"`` -> ``"::1"``, ``"LocalHost:80"`` -> ``"localhost"``."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[1:host.find("]")] if "]" in host else host
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


class _Guard:
    """ASGI middleware: the Host and Origin allow-lists for every request and the token
    for every ``/api/`` request (see the module docstring)."""

    def __init__(self, app: ASGIApp, token: str, hosts: tuple[str, ...]) -> None:
        self.app, self.token, self.hosts = app, token.encode(), hosts

    def _check(self, scope: Scope) -> None:
        headers = {k.decode("latin-1").lower(): v.decode("latin-1")
                   for k, v in scope.get("headers", [])}
        host = headers.get("host", "")
        if _host_name(host) not in self.hosts:
            raise _Refused(403, f"Host: {host[:80]!r} is not this app's address "
                                f"(allowed: {', '.join(self.hosts)})")
        origin = headers.get("origin")
        if origin is not None and origin != f"http://{host}":
            raise _Refused(403, f"Origin: {origin[:80]!r} is not this app's page; "
                                "other sites cannot use it")
        if scope["path"].startswith("/api/"):
            given = headers.get(TOKEN_HEADER)
            if given is None:
                query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
                given = (query.get("token") or [None])[0]
            if given is None or not hmac.compare_digest(given.encode("latin-1", "replace"),
                                                        self.token):
                raise _Refused(403, "token: missing or wrong; open the URL (with its "
                                    "?token=...) that `taut app` printed")

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "lifespan":
            await self.app(scope, receive, send)
            return
        if scope["type"] != "http":               # no websockets
            return
        try:
            self._check(scope)
        except _Refused as exc:
            await _error(exc.status, exc.line)(scope, receive, send)
            return
        await self.app(scope, receive, send)


async def _read_body(request: Request, limit: int, timeout: float) -> bytes:
    """The request body, refused past ``limit`` bytes as it streams in."""
    declared = request.headers.get("content-length")
    if declared is not None:
        try:
            if int(declared) > limit:
                raise _Refused(413, f"request: larger than {limit // 2**20} MiB")
        except ValueError:
            raise _Refused(400, "request: bad Content-Length") from None
    chunks, size = [], 0
    try:
        with anyio.fail_after(timeout):
            async for chunk in request.stream():
                size += len(chunk)
                if size > limit:
                    raise _Refused(413, f"request: larger than {limit // 2**20} MiB")
                chunks.append(chunk)
    except TimeoutError:
        raise _Refused(408, f"request: body not received within {timeout:g} s") from None
    return b"".join(chunks)


def _endpoint(pool: WorkerPool, name: str) -> Callable[[Request], Awaitable[Response]]:
    """The route of a view's POST endpoint: the JSON body, as it arrived, to a worker."""
    async def route(request: Request) -> Response:
        try:
            raw = await _json_body(request)
        except _Refused as exc:
            return _error(exc.status, exc.line)
        status, data = await pool.call(name, raw, receive=request.receive)
        return Response(data, status_code=status, media_type="application/json")
    return route


async def _json_body(request: Request) -> bytes:
    """A POST's body, refused unless it says it is JSON (checked by the worker)."""
    kind = request.headers.get("content-type", "").split(";")[0]
    if kind.strip().lower() != "application/json":
        raise _Refused(415, "Content-Type: must be application/json")
    return await _read_body(request, MAX_BODY, BODY_TIMEOUT_S)


def create_app(initial: dict[str, Any] | None = None, *,
               catalog: Catalog | None = None, token: str | None = None,
               hosts: tuple[str, ...] = (), workers: int | None = None,
               budget_s: float = BUDGET_S, max_jobs: int | None = None) -> Starlette:
    """The Starlette application.

    Parameters
    ----------
    initial : dict, optional
        A scenario mapping to open first (from ``taut app SCENARIO``); its view is
        chosen by its keys (:func:`taut.app.payload.kind_of_mapping`).
    catalog : Catalog, optional
        Where bundled examples come from (default: the source checkout's ``examples/``).
    token : str, optional
        The secret every ``/api/`` request must carry; default :func:`new_token`. The app
        keeps it in ``app.state.token`` (and its :class:`~taut.app.pool.WorkerPool` in
        ``app.state.pool``).
    hosts : tuple of str
        Host names accepted besides :data:`LOOPBACK_HOSTS` (the ``--host`` served on).
    workers : int, optional
        Worker processes computing requests at once (default
        :func:`taut.app.pool.default_size`: one per core, at most two).
    budget_s : float
        Time budget of one request, s.
    max_jobs : int, optional
        Planning jobs queued or running at once (default :data:`taut.app.jobs.MAX_JOBS`);
        more get HTTP 503 "busy".
    """
    catalog = catalog or Catalog()
    token = token or new_token()
    start = None if initial is None else {"kind": kind_of_mapping(initial), "mapping": initial}
    page = static_dir() / "index.html"
    pool = WorkerPool(workers or default_size(), float(budget_s), catalog.root)
    jobs = PlanJobs(pool) if max_jobs is None else PlanJobs(pool, max_jobs)

    async def index(request: Request) -> Response:
        return FileResponse(page, headers={"Cache-Control": "no-store"})

    async def get_catalog(request: Request) -> Response:
        return _JSON(catalog.names())

    async def get_initial(request: Request) -> Response:
        return _JSON({"initial": start})

    async def get_job(request: Request) -> Response:
        status, data = jobs.job(request.path_params["jid"])
        return Response(data, status_code=status, media_type="application/json")

    async def run_plan(request: Request) -> Response:
        try:
            raw = await _json_body(request)
        except _Refused as exc:
            return _error(exc.status, exc.line)
        status, data = await jobs.run(raw)
        return Response(data, status_code=status, media_type="application/json")

    routes: list[BaseRoute] = [Route("/", index), Route("/api/catalog", get_catalog),
                               Route("/api/initial", get_initial),
                               Route("/api/plan/job/{jid}", get_job),
                               Route("/api/plan/run", run_plan, methods=["POST"])]
    for view, actions in (("sheet", ("load", "fk", "ik", "simulate", "yaml")),
                          ("plan", ("load", "yaml")),
                          ("cdpr", ("load", "state", "workspace", "yaml"))):
        for action in actions:
            routes.append(Route(f"/api/{view}/{action}", _endpoint(pool, f"{view}.{action}"),
                                methods=["POST"]))
    routes.append(Mount("/static", StaticFiles(directory=str(static_dir())), name="static"))

    async def http_error(request: Request, exc: Exception) -> Response:
        code = getattr(exc, "status_code", 500)
        if code == 404:
            line = f"path: no page or endpoint {request.url.path[:200]!r}"
        elif code == 405:
            line = f"method: {request.method} is not allowed on {request.url.path[:200]!r}"
        else:
            line = f"request: {getattr(exc, 'detail', 'refused')}"
        return _error(code, line)

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        async with pool.running():
            yield

    app = Starlette(routes=routes, lifespan=lifespan,
                    exception_handlers={HTTPException: http_error})
    app.state.token = token
    app.state.pool = pool
    allowed = tuple(dict.fromkeys(LOOPBACK_HOSTS + tuple(h.lower() for h in hosts)))
    app.add_middleware(_Guard, token=token, hosts=allowed)
    return app


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


def serve(sock: socket.socket, app: Starlette, *, log_level: str = "critical") -> None:
    """Serve ``app`` on an already bound socket until interrupted (uvicorn; after Ctrl-C
    replies being sent get :data:`SHUTDOWN_S`, then every request still computing is
    cancelled and its worker killed). uvicorn's own log is off by default: the app logs
    its errors itself (logger ``taut.app``), and a request cut short by Ctrl-C is not
    one."""
    import uvicorn

    config = uvicorn.Config(app, log_level=log_level, access_log=False, lifespan="on",
                            timeout_graceful_shutdown=SHUTDOWN_S, server_header=False)
    uvicorn.Server(config).run(sockets=[sock])
