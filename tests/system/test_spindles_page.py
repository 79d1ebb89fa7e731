"""A multi-spindle station on the line's page, in a real headless browser.

A station of four spindles as real processes (router, recorder, acquisition with its edge
predictor, the rig as a multi-spindle system: CAN over udp_multicast, zenoh on loopback)
and the page's own (``serve dashboard``), alive before the rig tightens two cycles of program
2 with a preload window at its target (about half its runs NOK). Debian's chromium, driven by
playwright, must show in the station's last results each cycle as a row with the common
result the predictor put on ``cycles`` (its verdict and reasons), its four spindles' runs
below it (each run's spindle as heard on zenoh); in the part search, the part's four
tightenings with their spindles under their cycle's row with the common result the results
store holds; and a click on a spindle's run whose cycle's file is named by another spindle's
run must draw it, one more click overlaying its cycle's four curves, each as its recording
holds it (read here with mcap's own reader). Screenshots go to the test's folder
(``BOLTWATCH_DOCS_IMAGES=1``: also docs/images/run-cycle.png, the picture of
docs/how-to/line-page.md). Where chromium cannot be had the test skips with the reason.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from services.cli.station_supervisor import StationSupervisor
from shared.config import load_station
from shared.contract import CycleResult, TighteningResult, channels, keys
from shared.errors import StoreError
from shared.recordings import writing_path
from shared.results import ResultsQuery, ResultsStore, StoredResult, station_store
from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS, MISSING
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.live_station import open_client, wait_supervised
from tests.support.paths import REPO
from tests.support.station_files import write_station

pytestmark = pytest.mark.system

STATION = "st1"
SPINDLES = 4
CYCLES = 2
PAGE_TIMEOUT_MS = 60_000
#: spindles = 4, and program 2's runs stop near 40 kN, about half below this window: NOK
CHANGES = {
    "[station]\n": f"[station]\nspindles = {SPINDLES}\n",
    "max_time_s = 4.0\n": "max_time_s = 4.0\nforce_min_n = 40000.0\n",
}
SERVICES = {"recorder", "predictor", "acquisition", "dashboard"}
#: the station's last results, as drawn: each cycle row, then each spindle's row
LIVE_ROWS = """[...document.querySelectorAll('#station-st1 tr.cycle, #station-st1 tr.result')]
  .map((tr) => tr.classList.contains('cycle')
    ? ['cycle', Number(tr.dataset.sync), tr.dataset.cycleResult, tr.textContent]
    : ['run', Number(tr.dataset.run), Number(tr.dataset.spindle),
       tr.querySelector('.verdict').textContent])"""
FOUND_ROWS = LIVE_ROWS.replace("#station-st1 tr.result", "#found tr.found").replace(
    "#station-st1", "#found"
)


def _stored(target: Any) -> list[StoredResult]:
    try:
        with ResultsStore(target, create=False) as store:
            return store.find(ResultsQuery(stations=[STATION], oldest_first=True))
    except StoreError:
        return []  # the recorder has not made it yet


def _recorded(path: Path) -> dict[int, list[dict[str, Any]]]:
    """Each run's samples in the cycle's file (under its writing name while the recorder
    still writes it: the last cycle's, until its grace is over), read with mcap's own
    reader."""
    runs: dict[int, list[dict[str, Any]]] = defaultdict(list)
    if not path.is_file():
        path = writing_path(path)
    with path.open("rb") as handle:
        for _, _, message in make_reader(handle).iter_messages([f"boltwatch/{STATION}/samples"]):
            sample = json.loads(message.data)
            runs[sample["run_id"]].append(sample)
    return runs


def _expected_rows(cycles: list[CycleResult], results: list[TighteningResult]) -> list[list[Any]]:
    """The rows the page must draw of ``cycles`` (newest first), each above its spindles'
    runs (newest first: in the order their results came, reversed)."""
    rows: list[list[Any]] = []
    for cycle in sorted(cycles, key=lambda c: -c.time_ns):
        rows.append(["cycle", cycle.sync_id, cycle.result])
        spindles = [r for r in reversed(results) if r.sync_id == cycle.sync_id]
        rows += [["run", r.run_id, r.spindle, r.result] for r in spindles]
    return rows


def test_a_multi_spindle_station_s_cycles_on_the_line_page(tmp_path: Path) -> None:
    if not CHROMIUM.exists():
        pytest.skip(MISSING)
    sync_api = pytest.importorskip("playwright.sync_api")
    station_file = write_station(tmp_path, placement="edge", replacements=CHANGES)
    loaded = load_station(station_file)
    endpoint = loaded.config.zenoh.connect[0]
    supervisor = StationSupervisor(station_file, tmp_path / "logs")
    port = free_port()
    url = f"http://127.0.0.1:{port}/"
    exits = (0, -signal.SIGKILL)  # the rig ends by itself after its cycles
    supervisor.start("router", ["--listen", endpoint])
    session = open_client(endpoint)
    listener = Listener(session, STATION, (channels.RESULTS.topic, channels.CYCLES.topic))
    try:
        supervisor.start("recorder", ["--no-rerun"])
        supervisor.start("acquisition")
        supervisor.start("dashboard", ["--listen", f"127.0.0.1:{port}"])

        def alive() -> bool:  # the page's token: its subscriptions are declared
            replies = session.liveliness().get(keys.health_key(STATION, "*"))
            seen = {str(r.ok.key_expr).rsplit("/", 1)[-1] for r in replies if r.ok is not None}
            return seen >= SERVICES

        wait_supervised(supervisor, alive, "the services and the page alive", exits=exits)
        supervisor.start("rig", ["--runs", str(CYCLES), "--program", "2", "--first-run-id", "1000"])
        wait_supervised(
            supervisor,
            lambda: len(listener.of(channels.CYCLES.topic)) == CYCLES,
            f"{CYCLES} cycles' common results",
            timeout_s=60,
            exits=exits,
        )
        cycles: list[CycleResult] = listener.of(channels.CYCLES.topic)
        results: list[TighteningResult] = listener.of(channels.RESULTS.topic)
        assert len(results) == CYCLES * SPINDLES
        target = station_store(loaded)
        wait_supervised(
            supervisor,
            lambda: sum(s.cycle is not None for s in _stored(target)) == CYCLES * SPINDLES,
            "every spindle's result stored with its cycle",
            timeout_s=60,
            exits=exits,
        )
        stored = _stored(target)
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(url)
            page.wait_for_function(
                f"document.querySelectorAll('#station-st1 tr.cycle').length === {CYCLES}"
                " && !document.querySelector('#station-st1 .verdict.pending')",
                timeout=PAGE_TIMEOUT_MS,
            )
            live = page.evaluate(LIVE_ROWS)
            assert [row[:3] for row in live] == [row[:3] for row in _expected_rows(cycles, results)]
            assert [row for row in live if row[0] == "run"] == [
                row for row in _expected_rows(cycles, results) if row[0] == "run"
            ]
            for cycle in cycles:  # the common result's reasons, as the predictor said them
                (text,) = [row[3] for row in live if row[:2] == ["cycle", cycle.sync_id]]
                assert text.endswith(f"{cycle.result} {cycle.nok_reasons}".rstrip()), text
            page.locator("#station-st1").screenshot(path=str(tmp_path / "station.png"))
            _the_part_s_cycle(page, cycles[0], stored, tmp_path)
            _a_spindle_s_run_with_its_cycle(page, stored, tmp_path)
            browser.close()
    finally:
        listener.close()
        session.close()
        supervisor.stop_all(["rig", "acquisition", "dashboard", "recorder", "router"])
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        shutil.copyfile(tmp_path / "run-cycle.png", REPO / "docs" / "images" / "run-cycle.png")


def _the_part_s_cycle(
    page: Any, cycle: CycleResult, stored: list[StoredResult], shots: Path
) -> None:
    """The part search: the cycle's part's four tightenings, each with its spindle, under the
    cycle's row with the common result the store holds."""
    assert cycle.part_id is not None, "the rig names each cycle's part"
    page.fill("#part", cycle.part_id)
    page.press("#part", "Enter")
    page.wait_for_selector("#found tr.found", timeout=PAGE_TIMEOUT_MS)
    found = page.evaluate(FOUND_ROWS)
    part = [s for s in stored if s.result.part_id == cycle.part_id]
    assert len(part) == SPINDLES and {s.result.sync_id for s in part} == {cycle.sync_id}
    common = part[0].cycle
    assert common is not None and common.result == cycle.result
    assert found[0][:3] == ["cycle", cycle.sync_id, common.result]
    assert found[0][3].endswith(f"{common.result} {common.nok_reasons}".rstrip())
    newest_first = sorted(part, key=lambda s: (s.result.time_ns, s.result.run_id), reverse=True)
    assert found[1:] == [
        ["run", s.result.run_id, s.result.spindle, s.result.result] for s in newest_first
    ]
    page.locator("#found").screenshot(path=str(shots / "part-cycle.png"))
    page.click("#found button.close")


def _a_spindle_s_run_with_its_cycle(page: Any, stored: list[StoredResult], shots: Path) -> None:
    """A spindle's run whose file is its cycle's, named by another of its runs: drawn as
    recorded; its cycle's four runs overlaid one click away."""
    spindle_run = next(
        s
        for s in stored  # the first cycle's: its file is finished
        if s.recording and not Path(s.recording).name.startswith(f"st1_run{s.result.run_id}_")
    )
    run_id = spindle_run.result.run_id
    assert spindle_run.recording is not None
    recorded = _recorded(Path(spindle_run.recording))
    cycle = sorted(
        (s for s in stored if s.result.sync_id == spindle_run.result.sync_id),
        key=lambda s: s.result.spindle or 0,
    )
    page.click(f"#station-st1 tr.result[data-run='{run_id}']")
    page.wait_for_selector(
        f"#run[data-key='{STATION}/{run_id}'][data-ready='1']", timeout=PAGE_TIMEOUT_MS
    )
    assert page.evaluate("window.boltwatchRun.samples") == len(recorded[run_id]) > 100
    subtitle = page.locator("#run .figures").first.inner_text()
    assert f"spindle {spindle_run.result.spindle} of cycle {spindle_run.result.sync_id}" in subtitle
    page.click("#run button[data-mode=cycle]")
    page.wait_for_selector("#run[data-mode-ready='cycle']", timeout=PAGE_TIMEOUT_MS)
    overlaid = page.evaluate(
        "[window.boltwatchRun.side.runs.map((r) => [r.key, r.spindle, r.samples, r.reference,"
        " r.torque_nm[r.torque_nm.length - 1]]),"
        " Number(window.boltwatchRun.charts.torque_angle.canvas.dataset.lines)]"
    )
    assert overlaid == [
        [
            [
                f"{STATION}/{s.result.run_id}",
                s.result.spindle,
                len(recorded[s.result.run_id]),
                s.result.run_id == run_id,
                recorded[s.result.run_id][-1]["torque_nm"],
            ]
            for s in cycle
        ],
        SPINDLES,
    ]
    common = spindle_run.cycle
    assert common is not None
    summary = page.locator("#run .cycle-summary").inner_text()
    assert summary.endswith(f"the cycle: {common.result} {common.nok_reasons}".rstrip()), summary
    page.locator("#run").screenshot(path=str(shots / "run-cycle.png"))
    assert (shots / "run-cycle.png").stat().st_size > 10_000
