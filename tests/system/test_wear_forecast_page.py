"""The line's page shows the tools due soonest, each with its chart, in a real browser.

Six weeks of a simulated two-shift plant of three stations up to now in the
line's wear ledger (``tests/support/wear_plant.py``: each station's tool, its
services at the shift change after each crossing), then real processes: the
line's router, its recorder serving the three stations (it answers
``boltwatch/<st>/wear`` with each tool's line and outlook) and the page's own
(``serve dashboard``). Debian's chromium, driven by playwright, must show every
tool of the ledger in "Tools due soonest", the soonest first, each with its
forecast date, and a chart whose data is the ledger's: the intensity since
service day by day ending at the tool's intensity since service now, the
station's threshold, and the forecast line from now to the threshold on the
date the page states; and what it draws is that data (the line of the
intensity ends where the forecast line starts, the forecast line ends on the
threshold line). A screenshot goes to the test's folder
(``BOLTWATCH_DOCS_IMAGES=1``: also to docs/images/tools_due.png, the picture of
docs/how-to/line-page.md). Where chromium cannot be had the test skips with
the reason.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from services.cli.station_supervisor import stop_process
from shared.config import derive_stations
from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS, MISSING
from tests.support.dashboard_process import wait_http
from tests.support.live_recorder import free_port
from tests.support.paths import REPO
from tests.support.router_process import router_process
from tests.support.station_files import write_station
from tests.support.wear_plant import TWO_SHIFTS, ledger_forecasts, plant_until, write_ledger

pytestmark = pytest.mark.system

DOCS_IMAGE = REPO / "docs" / "images" / "tools_due.png"
PAGE_TIMEOUT_MS = 60_000
STATIONS = ("st1", "st2", "st3")
#: each row of "Tools due soonest": its tool, its state, its chart's data and drawing
ROWS = """[...document.querySelectorAll('#due tr.due-tool')].map((tr) => {
  const svg = tr.querySelector('svg.due-chart');
  const line = (name) => { const l = svg.querySelector(name); return l &&
    [l.x1.baseVal.value, l.y1.baseVal.value, l.x2.baseVal.value, l.y2.baseVal.value]; };
  return { tool: Number(tr.dataset.tool), state: tr.dataset.state,
    text: tr.innerText, chart: JSON.parse(svg.dataset.chart),
    since: svg.querySelector('polyline.since').getAttribute('points').split(' ')
      .map((p) => p.split(',').map(Number)),
    threshold: line('line.threshold'), forecast: line('line.forecast') };
})"""


@contextlib.contextmanager
def service(tmp_path: Path, name: str, arguments: list[str]) -> Iterator[subprocess.Popen[bytes]]:
    """``boltwatch serve NAME ARGUMENTS`` as a process, its log in ``tmp_path``; stopped with
    SIGTERM after."""
    log = (tmp_path / f"{name}.log").open("wb")
    process = subprocess.Popen(
        [sys.executable, "-m", "services.cli", "serve", name, *arguments],
        cwd=REPO,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    try:
        yield process
    finally:
        stop_process(process, grace_s=10)
        log.close()


def line_files(tmp_path: Path, port: int, threshold: float) -> list[Path]:
    base = write_station(
        tmp_path,
        zenoh_port=port,
        replacements={"[recorder]\n": f"[recorder]\nwear_service_threshold = {threshold}\n"},
    )
    return derive_stations(base, len(STATIONS), tmp_path / "line")


def test_the_page_shows_the_tools_due_soonest_with_the_ledgers_chart(tmp_path: Path) -> None:
    if not CHROMIUM.exists():
        pytest.skip(MISSING)
    sync_api = pytest.importorskip("playwright.sync_api")
    plant = plant_until(replace(TWO_SHIFTS, days=42, stations=3), 21, time.time_ns())
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    write_ledger(plant, recordings / "wear.sqlite")
    port = free_port()
    files = [str(path) for path in line_files(tmp_path, port, plant.threshold)]
    with (
        router_process(tmp_path, f"tcp/127.0.0.1:{port}"),
        service(tmp_path, "recorder", ["--config", *files]),
        service(tmp_path, "dashboard", ["--config", *files, "--listen", f"127.0.0.1:{port + 1}"]),
    ):
        url = f"http://127.0.0.1:{port + 1}/"
        wait_http(url, timeout_s=60.0)
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(url)
            page.wait_for_function(
                "document.querySelectorAll('#due tr.due-tool').length === 3",
                timeout=PAGE_TIMEOUT_MS,
            )
            rows: list[dict[str, Any]] = page.evaluate(ROWS)
            shot = tmp_path / "tools_due.png"
            page.locator("#due").screenshot(path=str(shot))
            browser.close()
    now_ns = time.time_ns()
    tools, ranked = ledger_forecasts(recordings / "wear.sqlite", plant.threshold, now_ns)
    expected = {told.tool_id: told for told in ranked}
    assert sorted(row["tool"] for row in rows) == sorted(tools) == [100, 101, 102]
    # the soonest first: due now, then by date, then those with no date
    assert [row["tool"] for row in rows] == [told.tool_id for told in ranked]
    for row in rows:
        tool, told, chart = tools[row["tool"]], expected[row["tool"]], row["chart"]
        assert row["state"] == told.state
        assert chart["threshold"] == pytest.approx(plant.threshold)
        points = chart["points"]
        assert points[-1][1] == pytest.approx(tool.intensity_since_service, rel=1e-9)
        assert [p[1] for p in points] == sorted(p[1] for p in points)  # it only grows
        assert tool.outlook is not None
        # from the service (times in ns pass through the page's JavaScript: 2^53 holds µs)
        assert abs(points[0][0] - tool.outlook.since_service[0][0]) < 1_000
        assert len(row["since"]) == len(points)  # one vertex a point, drawn
        drawn = [y for _, y in row["since"]]
        assert drawn == sorted(drawn, reverse=True)  # higher on the page as it grows
        assert row["threshold"][1] == row["threshold"][3] < drawn[-1] or told.state == "due"
        if told.state == "forecast":
            assert told.due_ns is not None
            due_ns = chart["forecast"][1][0]
            assert abs(due_ns - told.due_ns) < 3_600 * 1_000_000_000  # made a moment apart
            assert f"due {time.strftime('%Y-%m-%d', time.gmtime(due_ns / 1e9))}" in row["text"]
            start, end = row["forecast"][:2], row["forecast"][2:]
            assert start == pytest.approx(row["since"][-1], abs=0.01)  # from now's intensity
            assert end[1] == pytest.approx(row["threshold"][1], abs=0.01)  # to the threshold
        else:
            assert chart["forecast"] is None and row["forecast"] is None
    assert shot.stat().st_size > 5_000
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        DOCS_IMAGE.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(shot, DOCS_IMAGE)
