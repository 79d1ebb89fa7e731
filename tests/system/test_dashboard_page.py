"""``boltwatch serve dashboard`` in a real headless browser, on a real line.

A live station (router, recorder, acquisition with its edge predictor, rig:
real processes, :mod:`tests.support.live_station`) with a wear threshold its
tool reaches after about four runs (program 2: some 1.2e6 a run); the page's own process
(``serve dashboard``); Debian's chromium driven by playwright. The page must
show a result the test heard on zenoh (its run and its OK/NOK), then a newer
one without a reload, the station's services alive, the tool's wear as due
and the wear alert, and load nothing but from its own server. A screenshot
goes to the test's folder (``BOLTWATCH_DOCS_IMAGES=1``: also to
docs/images/dashboard.png, the picture of docs/how-to/line-page.md).

Chromium comes from Debian's package (.ci/run installs it as root when
missing); never ``playwright install``. Where it
cannot be installed the test skips with the reason.
"""

from __future__ import annotations

import os
import shutil
import time
import urllib.request
from pathlib import Path

import pytest

from shared.contract import channels
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.live_station import STATION, live_station
from tests.support.paths import REPO

pytestmark = pytest.mark.system

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
DOCS_IMAGE = REPO / "docs" / "images" / "dashboard.png"
PAGE_TIMEOUT_MS = 60_000


def _wait_http(url: str, timeout_s: float = 30.0) -> None:
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with urllib.request.urlopen(url, timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def test_the_line_page_shows_results_live_in_a_real_browser(tmp_path: Path) -> None:
    if not CHROMIUM.exists():
        pytest.skip(f"{CHROMIUM} is missing (.ci/run installs Debian's chromium as root)")
    sync_api = pytest.importorskip("playwright.sync_api")
    threshold = {"[recorder]\n": "[recorder]\nwear_service_threshold = 4.0e6\n"}
    with live_station(tmp_path, placement="edge", replacements=threshold) as station:
        listener = Listener(station.session, STATION, (channels.RESULTS.topic,))
        port = free_port()
        dashboard = station.supervisor.start("dashboard", ["--listen", f"127.0.0.1:{port}"])
        url = f"http://127.0.0.1:{port}/"
        _wait_http(url)
        requests: list[str] = []
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("request", lambda request: requests.append(request.url))
            page.goto(url)
            page.wait_for_selector("#station-st1 tr.result", timeout=PAGE_TIMEOUT_MS)
            first_run = int(page.locator("tr.result").first.get_attribute("data-run") or "0")
            # the same result the line put on zenoh: its run, its verdict
            station.wait_for(
                lambda: any(r.run_id == first_run for r in listener.of("results")),
                f"result of run {first_run} heard by the test",
            )
            heard = next(r for r in listener.of("results") if r.run_id == first_run)
            row = page.locator(f"tr.result[data-run='{first_run}']")
            assert row.locator(".verdict").inner_text() == heard.result
            assert page.locator("#station-st1 h2").inner_text() == f"Station {STATION}"
            # live: a newer result appears with no reload (the document stays the same)
            page.evaluate("window.notReloaded = true")
            page.wait_for_function(
                f"document.querySelector('tr.result').dataset.run !== '{first_run}'",
                timeout=PAGE_TIMEOUT_MS,
            )
            assert page.evaluate("window.notReloaded") is True
            # services alive (a window after start), the tool due, the recorder's alert
            for service in ("acquisition", "predictor", "recorder"):
                page.wait_for_selector(
                    f"span.alive[data-service='{service}']", timeout=PAGE_TIMEOUT_MS
                )
            page.wait_for_selector("tr.wear td.due", timeout=PAGE_TIMEOUT_MS)
            page.wait_for_function(
                "[...document.querySelectorAll('li.alert')]"
                ".some(li => li.textContent.startsWith('wear/alert: tool'))",
                timeout=PAGE_TIMEOUT_MS,
            )
            # the stop reason of a run, as its summary on zenoh says it
            summary = next(s for s in station.summaries() if s.run_id == first_run)
            stop_row = page.locator("tr.stop").filter(has_text=str(first_run)).first
            assert (summary.stop_reason or "tool (done)") in stop_row.inner_text()
            shot = tmp_path / "dashboard.png"
            page.screenshot(path=str(shot), full_page=True)
            browser.close()
        listener.close()
        assert station.supervisor.stop(dashboard) == 0, dashboard.log_tail()
    assert shot.stat().st_size > 10_000
    assert requests and all(u.startswith(url) for u in requests), requests
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        DOCS_IMAGE.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(shot, DOCS_IMAGE)
