"""Browser tests: skip (and say so at the end of the run) without Chromium/chromedriver."""

import pytest

_SKIPPED: list[str] = []


@pytest.fixture(scope="session")
def browser_paths() -> tuple[str, str]:
    """Chromium and chromedriver paths, or skip with the install command."""
    pytest.importorskip("selenium", reason="browser tests need the app-test extra: "
                        "pip install -e '.[app-test]'")
    pytest.importorskip("uvicorn", reason="browser tests need the app-test extra: "
                        "pip install -e '.[app-test]'")
    from taut.app.browser import find_browser

    found = find_browser()
    if found is None:
        pytest.skip("no Chromium/chromedriver: apt-get install -y chromium chromium-driver")
    return found


def pytest_runtest_logreport(report):
    if report.skipped and "browser" in report.keywords and report.when in ("setup", "call"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        _SKIPPED.append(reason.removeprefix("Skipped: "))


def pytest_terminal_summary(terminalreporter):
    if _SKIPPED:
        terminalreporter.write_line(f"browser tests SKIPPED ({len(_SKIPPED)}): {_SKIPPED[0]}",
                                    yellow=True)
