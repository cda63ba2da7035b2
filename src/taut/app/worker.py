"""The process that computes the app's requests (``python -m taut.app.worker [EXAMPLES]``).

The server (:mod:`taut.app.pool`) keeps a few of these and hands each request's raw body
to an idle one; the worker parses the JSON, runs the view's handler and renders the JSON
reply, so the server's event loop only moves bytes and a light request (the page, the
catalog) never waits for a heavy one's parsing or rendering. Killing a worker is how a
request is cancelled (client gone, time budget spent, Ctrl-C).

Each worker's address space is capped at :data:`MEMORY_LIMIT` bytes (``RLIMIT_AS``), so
no request can make the app use much more than that per worker; a request that needs more
gets HTTP 507.

Protocol on the worker's stdin/stdout (its stdout is private: anything printed goes to
stderr): a request is ``<H name length><Q body length><name><body>`` (body length
:data:`NO_BODY`: a GET without a body); a reply is ``<H status><Q length><JSON bytes>``.
A ready reply (status 0, no data) is sent once, after the imports.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import struct
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

from ..errors import TautError
from ..io.serialize import json_ready
from .payload import check_json

__all__ = ["MEMORY_LIMIT", "ASK", "REPLY", "NO_BODY", "render", "handle", "handlers",
           "main"]

log = logging.getLogger("taut.app")

#: Address space of one worker process, bytes (its imports take about 0.45 GiB of it).
MEMORY_LIMIT = 2**30
#: Request frame header: name length, body length.
ASK = struct.Struct("<HQ")
#: Reply frame header: HTTP status (0: ready), data length.
REPLY = struct.Struct("<HQ")
#: Body length of a request that has no body.
NO_BODY = 2**64 - 1

Handler = Callable[[dict[str, Any]], dict[str, Any]]


def render(content: Any) -> bytes:
    """JSON bytes without NaN (the page's JSON.parse rejects it): NaN/inf become null."""
    return json.dumps(json_ready(content), allow_nan=False,
                      separators=(",", ":")).encode("utf-8")


def handle(handler: Handler, raw: bytes | None, name: str) -> tuple[int, bytes]:
    """Parse, handle and render one request: ``(HTTP status, JSON bytes)``.

    200 with the handler's reply; 422 ``{"error": "<field>: <problem>"}`` for bad input;
    507 when it needs more memory than the worker has; 500 with a one-line error for a
    bug (logged with its traceback on stderr, never sent to the page).

    Examples
    --------
    >>> handle(lambda body: {"n": len(body["a"])}, b'{"a": [1, 2]}', "x")
    (200, b'{"n":2}')
    >>> handle(lambda body: {}, b'[1]', "x")
    (422, b'{"error":"request: must be a JSON object"}')
    """
    try:
        body = {} if raw is None else check_json(raw)
        return 200, render(handler(body))
    except TautError as exc:
        return 422, render({"error": str(exc)})
    except MemoryError:
        return 507, render({"error": f"request: needs more than the app's "
                                     f"{MEMORY_LIMIT / 2**30:g} GiB per request; try a "
                                     "smaller input"})
    except Exception as exc:               # a bug: log it here, one line to the page
        log.exception("internal error in %s", name)
        return 500, render({"error": f"internal error ({exc.__class__.__name__}); the "
                                     "server log has the details"})


def handlers(root: Path | None) -> dict[str, Handler]:
    """The views' endpoints by name (``"sheet.fk"``, ``"plan.crossing"``, ...), over the
    bundled examples in ``root``."""
    from .catalog import Catalog
    from .cdpr_api import CdprAPI
    from .plan_api import PlanAPI
    from .sheet_api import SheetAPI

    catalog = Catalog(root)
    apis: dict[str, tuple[Any, tuple[str, ...]]] = {
        "sheet": (SheetAPI(catalog), ("load", "fk", "ik", "simulate", "yaml")),
        "plan": (PlanAPI(catalog), ("load", "yaml", "check", "baseline", "crossing")),
        "cdpr": (CdprAPI(catalog), ("load", "state", "workspace", "yaml"))}
    return {f"{view}.{action}": getattr(api, action)
            for view, (api, actions) in apis.items() for action in actions}


def _read(stream: BinaryIO, n: int) -> bytes | None:
    data = stream.read(n)
    return data if len(data) == n else None


def _limit_memory() -> None:
    try:
        import resource
    except ImportError:                    # not on Windows: no cap there
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = MEMORY_LIMIT if hard == resource.RLIM_INFINITY else min(MEMORY_LIMIT, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def main(argv: list[str] | None = None) -> None:
    """Serve requests on stdin/stdout until stdin closes (the server went away)."""
    args = sys.argv[1:] if argv is None else argv
    signal.signal(signal.SIGINT, signal.SIG_IGN)    # the server stops us, not the terminal
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)                                    # stray prints go to stderr
    inp = sys.stdin.buffer
    logging.basicConfig(level=logging.WARNING, format="taut app worker: %(message)s")
    table = handlers(Path(args[0]) if args else None)
    _limit_memory()
    out.write(REPLY.pack(0, 0))
    out.flush()
    while (head := _read(inp, ASK.size)) is not None:
        name_len, body_len = ASK.unpack(head)
        name = (_read(inp, name_len) or b"").decode("utf-8", "replace")
        raw = None if body_len == NO_BODY else _read(inp, body_len)
        if body_len != NO_BODY and raw is None:
            break
        status, data = handle(table[name], raw, name)
        out.write(REPLY.pack(status, len(data)) + data)
        out.flush()


if __name__ == "__main__":
    main()
