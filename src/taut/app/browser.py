"""Driving the app in a real browser, for the browser tests, the latency benchmark and
the screenshots: the app served in a thread on a free localhost port, and headless
Chromium (Debian's ``chromium`` and ``chromium-driver``) driven by Selenium through the
system chromedriver. Needs the ``app-test`` extra; nothing here downloads a browser.
"""

from __future__ import annotations

import shutil
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["find_browser", "served", "chromium", "wait_for", "drag", "drag_at", "FLAGS"]

_CHROMIUM = ("/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome")
_CHROMEDRIVER = "/usr/bin/chromedriver"
#: Chromium flags that work as root on a machine without display or internet access;
#: WebGL (the app's 3D views) is rendered in software by SwiftShader, which Chromium
#: only uses when asked to (the page is the app's own, served from this machine).
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--window-size=1400,1100",
         "--enable-unsafe-swiftshader", "--use-angle=swiftshader")


def find_browser() -> tuple[str, str] | None:
    """Paths of Chromium and chromedriver, or None when either is missing."""
    binary = next((p for p in _CHROMIUM if Path(p).exists()), None) or shutil.which("chromium")
    driver = _CHROMEDRIVER if Path(_CHROMEDRIVER).exists() else shutil.which("chromedriver")
    return (binary, driver) if binary and driver else None


@contextmanager
def served(app: Any) -> Iterator[str]:
    """Serve ``app`` on a free localhost port in a thread; yields the page's URL with the
    app's token (``http://127.0.0.1:PORT/?token=...``)."""
    import uvicorn

    from .server import bind

    sock = bind("127.0.0.1", 0)
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started and time.monotonic() < deadline:
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{port}/?token={app.state.token}"
    finally:
        server.should_exit = True
        thread.join(10)
        sock.close()


@contextmanager
def chromium(binary: str, driver: str) -> Iterator[Any]:
    """A headless Chromium session with a fresh, temporary profile."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="taut-chromium-")
    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for f in FLAGS:
        opts.add_argument(f)
    opts.add_argument(f"--user-data-dir={profile}")
    d = webdriver.Chrome(options=opts, service=Service(executable_path=driver))
    d.set_script_timeout(30)
    try:
        yield d
    finally:
        d.quit()
        shutil.rmtree(profile, ignore_errors=True)


def wait_for(driver: Any, script: str, timeout: float = 20.0, poll: float = 0.05) -> Any:
    """Poll a JavaScript expression until it is truthy; return its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = driver.execute_script("return " + script)
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out waiting for: {script}")
        time.sleep(poll)


def drag(driver: Any, css: str, moves: list[tuple[int, int]], step_ms: int = 16) -> None:
    """Real pointer input: press on the element matching ``css``, move by each (dx, dy)
    pixel step (``step_ms`` per move), release."""
    from selenium.webdriver.common.actions.action_builder import ActionBuilder
    from selenium.webdriver.common.by import By

    from selenium.common.exceptions import StaleElementReferenceException

    for attempt in range(3):
        # The page may redraw the element between finding it and pressing on it (an
        # answer to an earlier request arriving): find it again and retry the press.
        ab = ActionBuilder(driver, duration=step_ms)
        ab.pointer_action.move_to(driver.find_element(By.CSS_SELECTOR, css)).pointer_down()
        for dx, dy in moves:
            ab.pointer_action.move_by(dx, dy)
        ab.pointer_action.pointer_up()
        try:
            ab.perform()
            return
        except StaleElementReferenceException:
            if attempt == 2:
                raise
            driver.execute_script("return 0")        # let the page finish its redraw


def drag_at(driver: Any, xy: tuple[float, float], moves: list[tuple[int, int]],
            step_ms: int = 16) -> None:
    """Real pointer input from a point of the page: press at ``xy`` (CSS pixels in the
    viewport, e.g. where a chart draws a point), move by each (dx, dy) step, release."""
    from selenium.webdriver.common.actions.action_builder import ActionBuilder

    ab = ActionBuilder(driver, duration=step_ms)
    ab.pointer_action.move_to_location(int(round(xy[0])), int(round(xy[1]))).pointer_down()
    for dx, dy in moves:
        ab.pointer_action.move_by(dx, dy)
    ab.pointer_action.pointer_up()
    ab.perform()
