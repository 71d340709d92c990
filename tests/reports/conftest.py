"""Fixtures of the report-page tests."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from typing import Any

import pytest
from pages import HOSTILE, HOSTILE_EVENT

from neurosym.record.recording import SCHEMA, Recording


@pytest.fixture(scope="session")
def hostile_recording(scripted_recording):  # noqa: ANN201
    """``hostile_recording()``: the scripted recording with an object type and an event only a
    hostile KB would have."""

    def hostile_recording() -> Recording:
        rec = scripted_recording("predinet")
        positions = rec.positions.copy()
        positions.loc[positions["type"] == "sword", "type"] = HOSTILE
        events = rec.events.copy()
        events.loc[events.index[0], "event"] = HOSTILE_EVENT
        tables = {name: rec.tables[name] for name in SCHEMA}
        return Recording(**{**tables, "positions": positions, "events": events}, meta=rec.meta)
    return hostile_recording


BROWSERS = ("chromium", "chromium-browser", "google-chrome")
INSTALL = "scripts/setup_browser.sh installs it (apt-get install chromium chromium-driver)"


def _browser() -> tuple[str, str]:
    binary = next((p for p in map(shutil.which, BROWSERS) if p), None)
    driver = shutil.which("chromedriver")
    if binary is None or driver is None:
        missing = "chromium" if binary is None else "chromedriver"
        pytest.skip(f"no headless browser: {missing} is not installed; {INSTALL}")
    return binary, driver


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    """A headless Chromium with its console log kept (selenium's WebDriver)."""
    binary, driver_path = _browser()
    webdriver = pytest.importorskip(
        "selenium.webdriver", reason="selenium: pip install -e '.[dev]'"
    )
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = binary
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,900", "--force-device-scale-factor=1"):  # fmt: skip
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()
