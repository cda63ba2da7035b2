"""Helpers for the browser tests: the app served in a thread on a free port, and a
headless Chromium driven by Selenium through the system chromedriver."""

from __future__ import annotations

import shutil
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

CHROMIUM = ("/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome")
CHROMEDRIVER = "/usr/bin/chromedriver"
#: The flags that work on a machine without a display or internet access.
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--window-size=1400,1100")


def browser_or_skip() -> tuple[str, str]:
    """Paths of Chromium and chromedriver, or skip the test with the install command."""
    pytest.importorskip("selenium", reason="browser tests need the app-test extra: "
                        "pip install -e '.[app-test]'")
    pytest.importorskip("uvicorn", reason="browser tests need the app extra")
    binary = next((p for p in CHROMIUM if Path(p).exists()), None) or shutil.which("chromium")
    driver = CHROMEDRIVER if Path(CHROMEDRIVER).exists() else shutil.which("chromedriver")
    if not binary or not driver:
        pytest.skip("browser tests skipped: no Chromium/chromedriver "
                    "(apt-get install -y chromium chromium-driver)")
    return binary, driver


@contextmanager
def served(app) -> Iterator[str]:
    """Serve ``app`` on a free localhost port in a thread; yields the base URL."""
    import uvicorn

    from taut.app.server import bind

    sock = bind("127.0.0.1", 0)
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started and time.monotonic() < deadline:
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{port}/"
    finally:
        server.should_exit = True
        thread.join(10)
        sock.close()


@contextmanager
def chromium(binary: str, driver: str) -> Iterator[object]:
    """A headless Chromium session with a fresh profile."""
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


def wait_for(driver, script: str, timeout: float = 20.0, poll: float = 0.05):
    """Poll a JavaScript expression until it is truthy; return its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = driver.execute_script("return " + script)
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for: {script}")
        time.sleep(poll)
