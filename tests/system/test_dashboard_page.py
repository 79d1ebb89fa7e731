"""``boltwatch serve dashboard`` in a real headless browser, on a real line.

A live station (router, recorder, acquisition with its edge predictor, rig:
real processes, :mod:`tests.support.live_station`) with a wear threshold its
tool reaches after about four runs (program 2: some 1.2e6 a run); the page's own process
(``serve dashboard``); Debian's chromium driven by playwright. The page must
show a result the test heard on zenoh (its run and its OK/NOK), then a newer
one without a reload, the station's services alive, the tool's wear as due
and the wear alert; a part id typed in its search box must show every
tightening of that part the results store holds (the recorder's
``results.sqlite``), newest first, with the verdicts heard on zenoh and their
recordings, a hostile part id as text (never run), and the page stay live
meanwhile; it loads nothing but from its own server. A screenshot
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
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from shared.contract import TighteningResult, channels
from shared.errors import StoreError
from shared.recordings import writing_path
from shared.results import ResultsQuery, ResultsStore, StoredResult, store_target
from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS, MISSING
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.live_station import STATION, LiveStation, live_station
from tests.support.paths import REPO

pytestmark = pytest.mark.system

DOCS_IMAGE = REPO / "docs" / "images" / "dashboard.png"
PAGE_TIMEOUT_MS = 60_000
#: a part id that is markup: shown as text, it never makes an element nor runs
HOSTILE_PART = '<img src=x onerror="window.hostileRan=1"><script>window.hostileRan=2</script>'
#: each row of the part search: station, run, verdict, recording
FOUND_ROWS = """[...document.querySelectorAll('#found tr.found')].map((tr) => [
  tr.dataset.station, Number(tr.dataset.run), tr.querySelector('.verdict').textContent,
  tr.querySelector('td.recording code').textContent])"""


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


def _search_a_part(
    page: Any,
    station: LiveStation,
    heard: Callable[[], list[TighteningResult]],
    first: TighteningResult,
) -> None:
    """The search box: the part of ``first`` shows every tightening the store holds of it,
    newest first, with the verdicts heard on zenoh, while the page stays live; a hostile
    part id shows as text."""
    part = first.part_id
    assert part is not None, "the rig names each run's part"
    station.wait_for(
        lambda: any(r.part_id not in (None, part) and r.run_id > first.run_id for r in heard()),
        f"part {part} tightened whole",
    )
    verdicts = {r.run_id: r.result for r in heard() if r.part_id == part}
    target = store_target(station.recordings, None)

    def stored() -> list[StoredResult]:
        try:
            with ResultsStore(target, create=False) as store:
                return store.find(ResultsQuery(part_id=part))
        except StoreError:
            return []  # the recorder has not made it yet

    station.wait_for(
        lambda: set(verdicts) <= {s.result.run_id for s in stored()}, f"part {part} stored"
    )
    found = stored()
    expected = [[STATION, s.result.run_id, s.result.result, s.recording] for s in found]
    assert first.run_id in {s.result.run_id for s in found} and len(found) > 1
    assert all(verdicts.get(s.result.run_id, s.result.result) == s.result.result for s in found)
    # each run's file, under its writing name while the recorder still writes it (the newest
    # run's file takes its name when the next run starts)
    assert all(
        s.recording is not None
        and (Path(s.recording).is_file() or writing_path(Path(s.recording)).is_file())
        for s in found
    )
    shown_run = page.locator("tr.result").first.get_attribute("data-run")
    page.fill("#part", f" {part} ")
    page.click("#part-search button")
    page.wait_for_function(
        f"document.querySelectorAll('#found tr.found').length === {len(found)}",
        timeout=PAGE_TIMEOUT_MS,
    )
    assert page.evaluate(FOUND_ROWS) == expected  # newest first
    summary = page.locator("#found .found-summary").inner_text()
    assert summary == f"{len(found)} tightenings, newest first"
    # still live: a newer result arrives on the stations' side, the search stays
    page.wait_for_function(
        f"document.querySelector('tr.result').dataset.run !== '{shown_run}'",
        timeout=PAGE_TIMEOUT_MS,
    )
    assert page.evaluate(FOUND_ROWS) == expected
    # markup in a part id is text: no element made, no script run
    page.fill("#part", HOSTILE_PART)
    page.press("#part", "Enter")
    page.wait_for_selector("#found p.none", timeout=PAGE_TIMEOUT_MS)
    assert page.locator("#found h2").inner_text() == f"Tightenings of part {HOSTILE_PART}"
    shown = page.locator("#found p.none").inner_text()
    assert shown == f"no tightening of part {HOSTILE_PART} in {target}"
    assert page.locator("#found img, #found script").count() == 0
    assert page.evaluate("window.hostileRan") is None
    page.fill("#part", part)  # the page's picture shows the part's tightenings
    page.press("#part", "Enter")
    page.wait_for_selector("#found tr.found", timeout=PAGE_TIMEOUT_MS)


def test_the_line_page_shows_results_live_in_a_real_browser(tmp_path: Path) -> None:
    if not CHROMIUM.exists():
        pytest.skip(MISSING)
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
            _search_a_part(page, station, lambda: listener.of("results"), heard)
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
