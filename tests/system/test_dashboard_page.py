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
meanwhile. Program 2 gets a preload window at its target, so about half its runs are NOK:
a click on a NOK result in the NOK list (NOK results only) must draw that run's curve as
its recording holds it (the file the results store names, read here with mcap's own
reader: its sample count in every chart, its last sample, its final values and verdict,
the preload window), the run's part's runs overlaid one more click away, every one the
store holds; a click on the newest of the station's last results opens its run too. The
page loads nothing but from its own server. Screenshots go to the test's folder
(``BOLTWATCH_DOCS_IMAGES=1``: also to docs/images/, dashboard.png, run-view.png and
run-part.png, the pictures of docs/how-to/line-page.md).

Chromium comes from Debian's package (.ci/run installs it as root when
missing); never ``playwright install``. Where it
cannot be installed the test skips with the reason.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from shared.contract import TighteningResult, channels
from shared.errors import StoreError
from shared.recordings import writing_path
from shared.results import ResultsQuery, ResultsStore, StoredResult, store_target
from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS, MISSING
from tests.support.dashboard_process import wait_http
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.live_station import STATION, LiveStation, live_station
from tests.support.paths import REPO

pytestmark = pytest.mark.system

DOCS_IMAGES = REPO / "docs" / "images"
#: program 2's runs stop near 40 kN, about half below it: NOK with this window
NOK_WINDOW = {"max_time_s = 4.0\n": "max_time_s = 4.0\nforce_min_n = 40000.0\n"}
PAGE_TIMEOUT_MS = 60_000
#: a part id that is markup: shown as text, it never makes an element nor runs
HOSTILE_PART = '<img src=x onerror="window.hostileRan=1"><script>window.hostileRan=2</script>'
#: each row of the part search: station, run, verdict, recording
FOUND_ROWS = """[...document.querySelectorAll('#found tr.found')].map((tr) => [
  tr.dataset.station, Number(tr.dataset.run), tr.querySelector('.verdict').textContent,
  tr.querySelector('td.recording code').textContent])"""


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
    # the answer, not the "searching…" line before it (a p.none too)
    page.wait_for_selector("#found p.none:has-text('no tightening')", timeout=PAGE_TIMEOUT_MS)
    assert page.locator("#found h2").inner_text() == f"Tightenings of part {HOSTILE_PART}"
    shown = page.locator("#found p.none").inner_text()
    assert shown == f"no tightening of part {HOSTILE_PART} in {target}"
    assert page.locator("#found img, #found script").count() == 0
    assert page.evaluate("window.hostileRan") is None
    page.fill("#part", part)  # the page's picture shows the part's tightenings
    page.press("#part", "Enter")
    page.wait_for_selector("#found tr.found", timeout=PAGE_TIMEOUT_MS)


def _stored(station: LiveStation, query: ResultsQuery) -> list[StoredResult]:
    try:
        with ResultsStore(store_target(station.recordings, None), create=False) as store:
            return store.find(query)
    except StoreError:
        return []  # the recorder has not made it yet


def _recorded(recording: str, run_id: int) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The run's samples and its result as its file holds them (under its writing name while
    the recorder still writes it), read with mcap's own reader."""
    path = Path(recording)
    if not path.is_file():
        path = writing_path(path)
    with path.open("rb") as handle:
        topics = ["boltwatch/st1/samples", "boltwatch/st1/results"]
        messages = [
            (channel.topic, json.loads(message.data))
            for _, channel, message in make_reader(handle).iter_messages(topics)
        ]
    samples = [m for topic, m in messages if topic.endswith("samples") and m["run_id"] == run_id]
    (result,) = [m for topic, m in messages if topic.endswith("results") and m["run_id"] == run_id]
    return samples, result


#: what the run's view drew, read in the browser
DRAWN = """(() => { const run = window.boltwatchRun, charts = run.charts;
  const main = charts.torque_angle.main();
  return { key: run.key, samples: run.samples, drawn: run.drawn,
    points: Object.values(charts).map((c) => Number(c.canvas.dataset.points)),
    last: [main.x[main.x.length - 1], main.y[main.y.length - 1]],
    windows: charts.force_time.spec.boxes.map((b) => b.y),
    torque: document.querySelector('#run tr[data-figure=torque] td.value').textContent,
    preload: document.querySelector('#run tr[data-figure=preload] td.value').textContent,
    verdict: document.querySelector('#run h2 .verdict').textContent,
    inked: (() => { const c = charts.torque_angle.canvas;
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0; for (let i = 0; i < d.length; i += 4) if (d[i] < 90 && d[i + 2] > 150) n++;
      return n; })() }; })()"""


def _a_nok_run_one_click_away(
    page: Any, station: LiveStation, heard: Callable[[], list[TighteningResult]], shots: Path
) -> None:
    """A click on a NOK result (in the NOK list) draws its curve as its recording holds it;
    one more overlays its part's runs; a row of the last results opens its run too."""
    station.wait_for(
        lambda: any(
            r.result == "NOK"
            and any(o.part_id not in (None, r.part_id) and o.run_id > r.run_id for o in heard())
            for r in heard()
        ),
        "a NOK result whose part was tightened whole",
        timeout_s=90,
    )
    nok = next(
        r
        for r in reversed(heard())
        if r.result == "NOK"
        and any(o.part_id not in (None, r.part_id) and o.run_id > r.run_id for o in heard())
    )
    part = ResultsQuery(part_id=nok.part_id)
    bolts = {r.run_id for r in heard() if r.part_id == nok.part_id}
    station.wait_for(
        lambda: bolts <= {s.result.run_id for s in _stored(station, part)}, "its part stored"
    )
    (stored_nok,) = _stored(station, ResultsQuery(stations=[STATION], run_id=nok.run_id))
    assert stored_nok.recording is not None
    samples, result = _recorded(stored_nok.recording, nok.run_id)
    # one click: on its row in the NOK list (which live updates never redraw under the click)
    page.click("#nok-list")
    row = f"#found tr.found[data-run='{nok.run_id}']"
    page.wait_for_selector(row, timeout=PAGE_TIMEOUT_MS)
    verdicts = page.evaluate(
        "[...document.querySelectorAll('#found tr.found .verdict')].map((v) => v.textContent)"
    )
    assert verdicts and set(verdicts) == {"NOK"}
    page.click(row)
    page.wait_for_selector(
        f"#run[data-key='{STATION}/{nok.run_id}'][data-ready='1']", timeout=PAGE_TIMEOUT_MS
    )
    drawn = page.evaluate(DRAWN)
    assert drawn["key"] == f"{STATION}/{nok.run_id}"
    assert drawn["samples"] == drawn["drawn"] == len(samples) > 100
    assert drawn["points"] == [len(samples)] * 4  # torque and preload, over angle and time
    assert drawn["last"] == [samples[-1]["angle_deg"], samples[-1]["torque_nm"]]
    assert drawn["verdict"] == result["result"] == "NOK"
    assert drawn["torque"] == f"{result['final_torque_nm']['value']:.1f} Nm"
    assert drawn["preload"] == f"{result['final_force_n']['value'] / 1000:.2f} kN"
    assert drawn["windows"] == [[40.0, None]] == [[result["final_force_n"]["min"] / 1000, None]]
    assert drawn["inked"] > 300, drawn["inked"]  # the curve is on the canvas
    page.locator("#run").screenshot(path=str(shots / "run-view.png"))
    # one more click: every bolt of its part, as the store holds them
    page.click("#run button[data-mode=part]")
    page.wait_for_selector("#run[data-mode-ready='part']", timeout=PAGE_TIMEOUT_MS)
    overlaid = page.evaluate(
        "[window.boltwatchRun.side.runs.map((r) => r.key),"
        " Number(window.boltwatchRun.charts.torque_angle.canvas.dataset.lines)]"
    )
    stored = _stored(station, part)
    assert overlaid == [[f"{STATION}/{s.result.run_id}" for s in stored], len(stored)]
    assert len(stored) == len(bolts) >= 2
    page.locator("#run").screenshot(path=str(shots / "run-part.png"))
    page.click("#run button.close")
    page.click("#found button.close")
    # a row of the station's last results opens its run as well (the newest, live)
    newest = page.locator("#station-st1 tr.result").first.get_attribute("data-run")
    its = ResultsQuery(stations=[STATION], run_id=int(newest or "0"))
    station.wait_for(lambda: bool(_stored(station, its)), f"run {newest} stored")  # flushed
    page.click(f"#station-st1 tr.result[data-run='{newest}']")
    page.wait_for_selector(
        f"#run[data-key='{STATION}/{newest}'][data-ready='1']", timeout=PAGE_TIMEOUT_MS
    )
    assert page.evaluate("window.boltwatchRun.samples") > 100
    page.click("#run button.close")


def test_the_line_page_shows_results_live_in_a_real_browser(tmp_path: Path) -> None:
    if not CHROMIUM.exists():
        pytest.skip(MISSING)
    sync_api = pytest.importorskip("playwright.sync_api")
    threshold = {"[recorder]\n": "[recorder]\nwear_service_threshold = 4.0e6\n"}
    with live_station(tmp_path, placement="edge", replacements=threshold | NOK_WINDOW) as station:
        listener = Listener(station.session, STATION, (channels.RESULTS.topic,))
        port = free_port()
        dashboard = station.supervisor.start("dashboard", ["--listen", f"127.0.0.1:{port}"])
        url = f"http://127.0.0.1:{port}/"
        wait_http(url, timeout_s=30.0)
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
            _a_nok_run_one_click_away(page, station, lambda: listener.of("results"), tmp_path)
            page.fill("#part", heard.part_id or "")  # the page's picture: a part's tightenings
            page.press("#part", "Enter")
            page.wait_for_selector("#found tr.found", timeout=PAGE_TIMEOUT_MS)
            shot = tmp_path / "dashboard.png"
            page.screenshot(path=str(shot), full_page=True)
            browser.close()
        listener.close()
        assert station.supervisor.stop(dashboard) == 0, dashboard.log_tail()
    for name in ("dashboard.png", "run-view.png", "run-part.png"):
        assert (tmp_path / name).stat().st_size > 10_000, name
    assert requests and all(u.startswith(url) for u in requests), requests
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        DOCS_IMAGES.mkdir(parents=True, exist_ok=True)
        for name in ("dashboard.png", "run-view.png", "run-part.png"):
            shutil.copyfile(tmp_path / name, DOCS_IMAGES / name)
