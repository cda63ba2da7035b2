"""The HTTP layer: JSON error contract (one line, no traceback, server keeps running),
static files (the vendored Plotly.js included) served, and `taut app` refusing a busy port with one line and exit 2."""

import json
import socket
from pathlib import Path

import pytest

pytest.importorskip("starlette", reason="needs the app extra: pip install -e '.[app-test]'")
pytest.importorskip("uvicorn", reason="needs the app extra: pip install -e '.[app-test]'")
testclient = pytest.importorskip("starlette.testclient",
                                 reason="needs httpx2: pip install -e '.[app-test]'")

from taut.app.catalog import Catalog  # noqa: E402
from taut.app.server import create_app, static_dir  # noqa: E402
from taut.cli import main  # noqa: E402

ROOT = Path(__file__).parents[2]


def local_client(app, **kw):
    """A test client that is the app's own page: loopback Host and the app's token."""
    return testclient.TestClient(app, base_url="http://127.0.0.1:8765",
                                 headers={"X-Taut-Token": app.state.token}, **kw)


@pytest.fixture(scope="module")
def client():
    with local_client(create_app(catalog=Catalog(ROOT / "examples"))) as c:
        yield c


def test_page_and_scripts_are_served(client):
    page = client.get("/")
    assert page.status_code == 200 and "<svg id=\"sheet-top\"" in page.text
    for name in ("common.js", "charts.js", "sheet.js", "sheet_draw.js", "plan.js", "cdpr.js",
                 "view3d.js", "main.js", "app.css"):
        assert (static_dir() / name).is_file()
        assert client.get(f"/static/{name}").status_code == 200
        assert f"/static/{name}" in page.text
    assert "http" not in "".join((static_dir() / n).read_text() for n in
                                 ("common.js", "main.js")).replace("http://www.w3.org", "")


def test_vendored_charts_are_served_as_recorded(client):
    """Plotly.js is shipped in the package (no CDN): the page loads it from /static, the
    file's sha256 is the one its README records, and its licence ships beside it."""
    import hashlib
    import re
    vendor = static_dir() / "vendor"
    page = client.get("/").text
    assert '<script src="/static/vendor/plotly-gl3d.min.js">' in page
    assert not re.search(r"""src=["']?(https?:)?//""", page)
    readme = (vendor / "README.md").read_text()
    for name in ("plotly-gl3d.min.js", "plotly-LICENSE.txt"):
        digest = hashlib.sha256((vendor / name).read_bytes()).hexdigest()
        assert re.search(rf"`{re.escape(name)}`.*`{digest}`", readme), name
        assert client.get(f"/static/vendor/{name}").status_code == 200
    assert "MIT" in (vendor / "plotly-LICENSE.txt").read_text()


def test_catalog_lists_the_examples(client):
    cat = client.get("/api/catalog").json()
    assert "example2_r2_r4_353mm.yaml" in cat["sheet"]
    assert "paper_corridor.yaml" in cat["plan"] and "fastkit" in cat["cdpr"]


@pytest.mark.parametrize("path, body, line", [
    ("/api/sheet/load", b"{not json", "request: is not valid JSON"),
    ("/api/sheet/load", b"[1, 2]", "request: must be a JSON object"),
    ("/api/sheet/load", json.dumps({"example": "nope.yaml"}).encode(),
     "example: no bundled sheet scenario named 'nope.yaml'"),
    ("/api/sheet/fk", json.dumps({"sheet": [[0, 0], [1, 0]], "hold_height": 1,
                                  "formation": [[0, 0], [1, 0]]}).encode(), None),
    ("/api/cdpr/state", json.dumps({"model": {"name": "x"}, "pose": [0] * 6}).encode(), None),
])
def test_bad_requests_get_one_line(client, path, body, line):
    r = client.post(path, content=body, headers={"Content-Type": "application/json"})
    assert r.status_code == 422
    err = r.json()["error"]
    assert "\n" not in err and "Traceback" not in err and ": " in err
    if line is not None:
        assert err == line


def test_a_bug_is_one_line_and_the_server_goes_on(client, caplog):
    """A handler's bug is a one-line 500 (details only in the server's log); the worker
    process that computes requests goes on serving."""
    from taut.app.worker import handle

    def boom(body):
        raise ZeroDivisionError("secret detail")

    status, data = handle(boom, b"{}", "sheet.fk")
    err = json.loads(data)["error"]
    assert status == 500 and err.startswith("internal error (ZeroDivisionError)")
    assert "secret" not in err and "secret detail" in caplog.text
    assert client.get("/api/catalog").status_code == 200
    assert client.post("/api/sheet/load", json={"regular": 4}).status_code == 200


def test_infeasible_answers_are_json_without_nan(client):
    ex = client.post("/api/cdpr/load", json={"example": "fastkit"}).json()
    r = client.post("/api/cdpr/state", json={"model": ex["model"], "pose": [0, 0, 2.35, 0, 0, 0]})
    assert r.status_code == 200 and "NaN" not in r.text
    assert r.json()["feasible"] is False


def test_initial_scenario_opens_its_view():
    data = {"hold_height": 1.0, "sheet": [[0, 0], [1, 0], [0, 1]]}
    with local_client(create_app(data)) as c:
        assert c.get("/api/initial").json()["initial"] == {"kind": "sheet", "mapping": data}


def test_busy_port_is_one_line_exit_2(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        code = main(["app", "--port", str(port)])
    err = capsys.readouterr().err
    assert code == 2
    assert err == (f"taut: error: --port: port {port} on 127.0.0.1 is already in use; "
                   "choose another with --port\n")


def test_bad_scenario_file_fails_before_serving(tmp_path, capsys):
    bad = tmp_path / "s.yaml"
    bad.write_text("hold_height: 0\nsheet: [[0, 0], [1, 0], [0, 1]]\n")
    assert main(["app", str(bad), "--port", "0"]) == 2
    assert capsys.readouterr().err == "taut: error: hold_height: must be positive, got 0\n"
