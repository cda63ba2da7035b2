"""A real `taut app` on a loopback port, attacked as a hostile web page and a careless
client would (issue 24): cross-origin and DNS-rebinding requests, missing tokens,
non-JSON POSTs, oversized and slow bodies, a flood of planning jobs, the nine inputs that
used to give HTTP 500, YAML injection through a model name, and light requests that must
answer while a heavy one runs.

Every server here listens on 127.0.0.1 only; every loop is bounded.
"""

import http.client
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import numpy as np
import pytest
import yaml

pytest.importorskip("starlette", reason="needs the app extra: pip install -e '.[app-test]'")
pytest.importorskip("uvicorn", reason="needs the app extra: pip install -e '.[app-test]'")

from taut.app.catalog import regular_team  # noqa: E402
from taut.app.server import MAX_BODY  # noqa: E402

ROOT = Path(__file__).parents[2]
TAUT = Path(sys.executable).with_name("taut")


def start_app(*args, env=None):
    """`taut app --port 0` as its own process; returns (process, port, token)."""
    proc = subprocess.Popen([str(TAUT), "app", "--port", "0", *args], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    line = proc.stdout.readline()
    if "serving on" not in line:
        proc.kill()
        pytest.fail(f"taut app did not start: {line!r} {proc.stderr.read()[:2000]}")
    url = urlparse(line.split("serving on ")[1].split()[0])
    assert url.hostname == "127.0.0.1"            # loopback by default
    return proc, url.port, parse_qs(url.query)["token"][0]


def stop(proc):
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(15)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(5)


@pytest.fixture(scope="module")
def app():
    proc, port, token = start_app()
    yield proc, port, token
    stop(proc)


def request(port, method, path, body=None, headers=None, timeout=60.0):
    """One HTTP request; returns (status, headers, parsed JSON or text, seconds)."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    h = {"Host": f"127.0.0.1:{port}"}
    h.update(headers or {})
    data = body if body is None or isinstance(body, bytes) else json.dumps(body).encode()
    t0 = time.perf_counter()
    conn.request(method, path, body=data, headers=h)
    resp = conn.getresponse()
    raw = resp.read()
    dt = time.perf_counter() - t0
    conn.close()
    try:
        out = json.loads(raw)
    except ValueError:
        out = raw.decode("utf-8", "replace")
    return resp.status, {k.lower(): v for k, v in resp.getheaders()}, out, dt


def api(port, token, path, body=None, method="POST", **kw):
    headers = {"X-Taut-Token": token}
    if method == "POST":
        headers["Content-Type"] = "application/json"
    headers.update(kw.pop("headers", {}))
    return request(port, method, path, body, headers, **kw)


# --- who may drive it ---------------------------------------------------------------

def test_api_needs_the_token(app):
    _, port, token = app
    st, _, out, _ = request(port, "GET", "/api/initial")
    assert st == 403 and out["error"].startswith("token: ")
    st, _, out, _ = request(port, "GET", "/api/initial", headers={"X-Taut-Token": "x" * 43})
    assert st == 403 and out["error"].startswith("token: ")
    assert api(port, token, "/api/initial", method="GET")[0] == 200
    assert request(port, "GET", f"/api/initial?token={token}")[0] == 200
    # the page itself is public (it holds no data); its API calls are not
    assert request(port, "GET", "/")[0] == 200


def test_cross_site_text_plain_post_is_refused(app):
    """The browser attack of the issue: a `text/plain` POST (no pre-flight) from another
    site, first with its own Host (DNS rebinding), then with the app's Host."""
    _, port, token = app
    body = json.dumps({"example": "example2_r2_r4_353mm.yaml"}).encode()
    for host in ("evil.example", f"evil.example:{port}", f"127.0.0.1:{port}"):
        st, hdr, out, _ = request(port, "POST", "/api/sheet/load", body,
                                  {"Host": host, "Origin": "http://evil.example",
                                   "Content-Type": "text/plain"})
        assert st == 403, host
        assert "error" in out and "access-control-allow-origin" not in hdr
    # even with the token (leaked into a link), another origin is refused
    st, _, out, _ = api(port, token, "/api/sheet/load", body,
                        headers={"Origin": "http://evil.example"})
    assert st == 403 and out["error"].startswith("Origin: ")
    # the page's own origin is fine
    st, _, out, _ = api(port, token, "/api/sheet/load", body,
                        headers={"Origin": f"http://127.0.0.1:{port}"})
    assert st == 200 and "scenario" in out


def test_rebinding_host_cannot_read_replies(app):
    _, port, token = app
    for path in ("/api/initial", "/api/catalog", "/", "/static/common.js"):
        st, _, out, _ = request(port, "GET", path, headers={
            "Host": f"attacker.example:{port}", "X-Taut-Token": token})
        assert st == 403 and out["error"].startswith("Host: "), path
    for host in (f"localhost:{port}", f"LOCALHOST:{port}"):
        assert request(port, "GET", "/api/catalog",
                       headers={"Host": host, "X-Taut-Token": token})[0] == 200


def test_post_must_be_json_and_no_cors(app):
    _, port, token = app
    for kind in ("text/plain", "application/x-www-form-urlencoded", "multipart/form-data"):
        st, hdr, out, _ = api(port, token, "/api/sheet/load", b"{}",
                              headers={"Content-Type": kind})
        assert st == 415 and out["error"].startswith("Content-Type: ")
    st, hdr, out, _ = request(port, "OPTIONS", "/api/sheet/load", headers={
        "X-Taut-Token": token, "Origin": f"http://127.0.0.1:{port}",
        "Access-Control-Request-Method": "POST"})
    assert st == 405 and "access-control-allow-origin" not in hdr
    assert out["error"].startswith("method: ")


def test_404_and_405_are_json(app):
    _, port, token = app
    st, hdr, out, _ = api(port, token, "/api/nothing", method="GET")
    assert st == 404 and hdr["content-type"].startswith("application/json")
    assert out["error"].startswith("path: ")
    st, _, out, _ = api(port, token, "/static/nothing.js", method="GET")
    assert st == 404 and out["error"].startswith("path: ")
    st, hdr, out, _ = api(port, token, "/api/sheet/fk", method="GET")
    assert st == 405 and out["error"].startswith("method: GET")


# --- bodies -------------------------------------------------------------------------

def read_reply(s):
    """A whole HTTP reply from a socket (headers, then Content-Length bytes)."""
    data = b""
    while b"\r\n\r\n" not in data and len(data) < 2**16:
        part = s.recv(65536)
        if not part:
            break
        data += part
    head, _, rest = data.partition(b"\r\n\r\n")
    length = next((int(line.split(b":")[1]) for line in head.split(b"\r\n")
                   if line.lower().startswith(b"content-length:")), 0)
    while len(rest) < length:
        part = s.recv(65536)
        if not part:
            break
        rest += part
    return (head + b"\r\n\r\n" + rest).decode("latin-1")


def rss_kib(pid):
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def test_oversized_bodies_are_refused_while_streaming(app):
    proc, port, token = app
    before = rss_kib(proc.pid)
    head = (f"POST /api/sheet/load HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
            f"X-Taut-Token: {token}\r\nContent-Type: application/json\r\n")
    # 1. declared 256 MiB: refused before any of it is sent
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall((head + f"Content-Length: {256 * 2**20}\r\n\r\n").encode())
        reply = read_reply(s)
    assert reply.startswith("HTTP/1.1 413") and "larger than 8 MiB" in reply
    # 2. chunked, no length: 12 MiB streamed and the body left unfinished; the 413 is
    # already there (the server did not wait for the end of the body)
    chunk = b"[" + b"1," * (2**20 // 2 - 1) + b"1]"
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall((head + "Transfer-Encoding: chunked\r\n\r\n").encode())
        try:
            for _ in range(12):
                s.sendall(f"{len(chunk):x}\r\n".encode() + chunk + b"\r\n")
        except (BrokenPipeError, ConnectionResetError):
            pass
        reply = read_reply(s)
    assert reply.startswith("HTTP/1.1 413") and "larger than 8 MiB" in reply
    assert rss_kib(proc.pid) - before < 200 * 1024          # < 200 MiB more memory
    assert request(port, "GET", "/api/catalog", headers={"X-Taut-Token": token})[0] == 200


def test_slow_body_times_out():
    """A body that trickles in is cut off after the body time limit (here 1 s)."""
    from taut.app import server
    from taut.app.browser import served
    from taut.app.catalog import Catalog

    old = server.BODY_TIMEOUT_S
    server.BODY_TIMEOUT_S = 1.0
    try:
        app = server.create_app(catalog=Catalog(ROOT / "examples"))
        with served(app) as url:
            port = urlparse(url).port
            with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                s.sendall((f"POST /api/sheet/load HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                           f"X-Taut-Token: {app.state.token}\r\n"
                           "Content-Type: application/json\r\nContent-Length: 100\r\n\r\n{")
                          .encode())
                t0 = time.perf_counter()
                reply = read_reply(s)
                waited = time.perf_counter() - t0
    finally:
        server.BODY_TIMEOUT_S = old
    assert reply.startswith("HTTP/1.1 408") and "body not received within 1 s" in reply
    assert 0.8 < waited < 5


# --- the nine inputs that gave HTTP 500 ------------------------------------------------

SHEET = [[0, 0], [1000, 0], [0, 1000]]


@pytest.mark.parametrize("path, body, field", [
    ("/api/sheet/load", {"text": "a: 1", "filename": ".."}, "filename"),
    ("/api/sheet/load", {"text": "a: 1", "filename": "a\x00b.yaml"}, "filename"),
    ("/api/sheet/load", {"text": "a: 1", "filename": "a" * 300 + ".yaml"}, "filename"),
    ("/api/sheet/load", {"text": "a: 1", "filename": "../../etc/x.yaml"}, "filename"),
    ("/api/sheet/load", '{"text": "a: \\ud800", "filename": "a.yaml"}', "text"),
    ("/api/sheet/fk", {"sheet": [["a", "b"]] * 3, "hold_height": 1000,
                       "formation": SHEET}, "sheet"),
    ("/api/sheet/fk", {"sheet": [{"x": 0}] * 3, "hold_height": 1000,
                       "formation": SHEET}, "sheet"),
    ("/api/sheet/fk", '{"sheet": ' + "[" * 100_000 + "]" * 100_000 + "}", "request"),
    ("/api/cdpr/state", {"model": "M", "pose": ["a"] * 6}, "pose"),
    ("/api/cdpr/yaml", {"model": "M", "pose": [0, 0, 1]}, "pose"),
    ("/api/sheet/fk", {"sheet": SHEET, "hold_height": 1000,
                       "formation": [[0, 0], [1, 0], [0, "x"]]}, "formation"),
    ("/api/sheet/ik", {"sheet": SHEET, "hold_height": 1000, "target": [1, "a", 3]},
     "target"),
])
def test_bad_inputs_are_422_naming_the_field(app, path, body, field):
    _, port, token = app
    if isinstance(body, dict) and body.get("model") == "M":
        model = api(port, token, "/api/cdpr/load", {"example": "fastkit"})[2]["model"]
        body = dict(body, model=model)
    raw = body.encode() if isinstance(body, str) else json.dumps(body).encode()
    st, hdr, out, _ = api(port, token, path, raw)
    assert st == 422, out
    assert out["error"].startswith(f"{field}: ") and "\n" not in out["error"]


def test_model_name_cannot_inject_yaml_keys(app):
    _, port, token = app
    model = api(port, token, "/api/cdpr/load", {"example": "fastkit"})[2]["model"]
    model = dict(model, name="x'\ninjected: 1\n#")
    st, _, out, _ = api(port, token, "/api/cdpr/yaml",
                        {"model": model, "pose": [0, 0, 0.8, 0, 0, 0]})
    assert st == 200
    back = yaml.safe_load(out["yaml"])
    assert "injected" not in back and back == model


def test_alias_bomb_upload_is_refused_fast(app):
    _, port, token = app
    bomb = "a: &a [" + ",".join(["x"] * 9) + "]\n" + "".join(
        f"{k}: &{k} [" + ",".join([f"*{p}"] * 9) + "]\n"
        for p, k in zip("abcdefgh", "bcdefghi"))
    st, _, out, dt = api(port, token, "/api/cdpr/load",
                         {"text": bomb, "filename": "bomb.yaml"})
    assert st == 422 and out["error"].startswith("bomb.yaml: YAML aliases add more than")
    assert dt < 2.0


# --- light requests answer while a heavy one runs ----------------------------------------

def heavy_body(steps=15000):
    m = regular_team(12)
    f0 = np.array(m["formation"])
    path = [(f0 + 30 * np.sin(2 * np.pi * k / 400) * np.array([1, 0])).round(3).tolist()
            for k in range(steps)]
    return {"sheet": m["sheet"], "hold_height": m["hold_height"], "mass": 1.0,
            "formations": path}


def fk_1000_body():
    """FK of a 1000-robot team (the library's most robots): the issue's heavy request."""
    from taut.sheet import Sheet
    sheet = Sheet.regular(1000, 1000.0)
    f = 0.8 * sheet.vertices + np.random.default_rng(0).uniform(-0.5, 0.5, (1000, 2))
    return {"sheet": np.round(sheet.vertices, 6).tolist(), "hold_height": 1000.0,
            "mass": 1.0, "formation": np.round(f, 6).tolist()}


def test_light_requests_answer_while_a_heavy_one_runs(app):
    """Three FK requests of 1000 robots back to back (on main `GET /api/catalog` waited
    behind each); the catalog, a script and the page answer in under 0.5 s meanwhile."""
    _, port, token = app
    body = json.dumps(fk_1000_body()).encode()
    assert api(port, token, "/api/sheet/fk", body, timeout=120)[0] == 200   # compiled
    result = []

    def heavy():
        for _ in range(3):
            result.append(api(port, token, "/api/sheet/fk", body, timeout=120))

    t = threading.Thread(target=heavy)
    t.start()
    time.sleep(0.1)
    light = []
    while t.is_alive() and len(light) < 300:
        for path in ("/api/catalog", "/static/common.js", "/"):
            st, _, _, dt = api(port, token, path, method="GET")
            assert st == 200
            light.append((path, dt, t.is_alive()))
        time.sleep(0.02)
    t.join(120)
    assert [r[0] for r in result] == [200] * 3
    assert all(r[2]["feasible"] for r in result)
    during = [dt for _, dt, alive in light if alive]
    assert len(during) >= 3, "the heavy requests finished too soon to test anything"
    assert max(during) < 0.5, light


# --- planning jobs ---------------------------------------------------------------------

def test_job_flood_is_bounded_and_ids_stay_valid(app):
    _, port, token = app
    sc = api(port, token, "/api/plan/load", {"example": "paper_corridor.yaml"})[2]["scenario"]
    replies = [api(port, token, "/api/plan/run", {"scenario": sc}) for _ in range(10)]
    ok = [r[2]["job"] for r in replies if r[0] == 200]
    busy = [r for r in replies if r[0] == 503]
    assert 1 <= len(ok) <= 4 and len(ok) + len(busy) == 10
    assert all(r[2]["error"].startswith("plan: busy") for r in busy)
    # every accepted id answers (queued or running) however many were refused
    for jid in ok:
        st, _, out, _ = api(port, token, f"/api/plan/job/{jid}", method="GET")
        assert st == 200 and out["state"] in ("running", "done", "error")


# --- Ctrl-C ------------------------------------------------------------------------------

def test_ctrl_c_stops_the_app_during_a_heavy_request():
    proc, port, token = start_app()
    body = json.dumps(heavy_body()).encode()          # a simulation of several seconds
    t = threading.Thread(target=lambda: _quiet(api, port, token, "/api/sheet/simulate", body),
                         daemon=True)
    t.start()
    time.sleep(0.5)
    t0 = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    proc.wait(20)
    assert time.perf_counter() - t0 < 6.0
    assert proc.returncode == 130
    assert proc.stderr.read() == "taut: interrupted\n"
    t.join(5)


def _quiet(fn, *args):
    try:
        fn(*args)
    except OSError:
        pass
