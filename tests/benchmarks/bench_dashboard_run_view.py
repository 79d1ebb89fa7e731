"""The line's page, a run's curve: its time to ready in a real browser, on a line server at
load, and what the browsing costs the line (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_dashboard_run_view.py [--stations 20]
        [--samples 3000] [--per-phase 10] [--browsers 4]

One router, one ``serve recorder --no-rerun`` for N + 1 station files (derived as ``up
--stations`` derives them) and ``serve dashboard`` for all of them, as on a line server.
Station st1's recordings hold the runs the browsers open, ``--samples`` samples each,
written by the real recorder (:func:`~tests.benchmarks.run_recordings.record_runs`) and
stored as ``results rebuild`` stores them. The load is ``bench_line.py``'s generator:
what N edge stations publish toward the line, at their rates (a ``SampleBatch`` every
50 ms, 1000 samples a second a station, events, tool states, decisions, summaries), which
the recorder files meanwhile. Debian's chromium (playwright) runs on the same box at nice
19 (``--browser-nice``: a browser on the engineer's PC takes no CPU from the line server;
0 puts it beside the line's services) and opens runs by the address (``#run=st1/N``, the
handler a click on a result row runs), one after the other per browser, each run opened
once (cold: the page has not read it) unless said; each browser's first open (its
scripts compiled) is not counted:

1. ``quiet``: the line's services idle, one browser, cold; then ``quiet warm``: the same
   runs again (kept by the page);
2. ``load``: the generator on, one browser, cold; ``load, B browsers``: B browsers at
   once, each its own runs, cold; ``load warm``: one browser, runs opened before.

Per open, the page's own figures: from the click's handler to the run's four charts
drawn and the frame that shows them begun (``window.boltwatchRun.readyMs``), and the part
of it that was the page's answer (asked, received, parsed: ``fetchMs``). Meanwhile a
thread asks ``/board.json`` every 100 ms (the page stays responsive: its answer's time),
and the recorder's ``RecorderStats`` give its lag and the samples missing (the live path
does not wait on the page), side by side with a stretch at load with nobody browsing;
the CPU of the recorder and of the page's process, by phase.
Exit status 1 when the goal is missed: at load, one browser, cold, p95 <= 300 ms.
"""

from __future__ import annotations

import argparse
import asyncio
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import zenoh

if TYPE_CHECKING:
    from playwright.async_api import Page

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process
from shared.config import derive_stations, load_station
from shared.contract import channels
from shared.results import ResultsStore, store_target
from shared.results.recordings_reading import fill_from_recordings, station_recordings
from shared.runtime import zenoh_config
from tests.benchmarks.bench_line import EDGE_PROGRAM, RecorderHeard, cpu_s, wait_alive
from tests.benchmarks.run_recordings import record_runs
from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS
from tests.support.free_ports import free_tcp_port
from tests.support.station_files import serve

GOAL_P95_MS = 300.0
BOARD_EVERY_S = 0.1
#: a failure past it, not a figure
OPEN_TIMEOUT_MS = 60_000
QUIET_LOAD_S = 10.0  # at load with nobody browsing: the recorder's figures to compare with


@dataclass
class BoardProbe:
    """``GET /board.json`` every :data:`BOARD_EVERY_S` from a thread: each answer's time,
    by phase."""

    url: str
    phase: str = "start"
    times_ms: dict[str, list[float]] = field(default_factory=dict)
    stop: threading.Event = field(default_factory=threading.Event)

    def run(self) -> None:
        while not self.stop.wait(BOARD_EVERY_S):
            started = time.perf_counter()
            with urllib.request.urlopen(self.url, timeout=30) as response:
                response.read()
            elapsed = (time.perf_counter() - started) * 1000
            self.times_ms.setdefault(self.phase, []).append(elapsed)


async def open_runs(page: Page, runs: list[int], fetches: list[float]) -> list[float]:
    """Open each run by the address, one after the other; each one's time to ready (ms), and
    in ``fetches`` the part of it that was the page's answer (asked, received, parsed)."""
    times = []
    for run in runs:
        key = f"st1/{run}"
        await page.evaluate(f"location.hash = '#run={key}'")
        await page.wait_for_function(
            f"window.boltwatchRun && window.boltwatchRun.key === '{key}'"
            " && window.boltwatchRun.readyMs !== null"
            f" && document.getElementById('run').dataset.key === '{key}'",
            timeout=OPEN_TIMEOUT_MS,
        )
        ready, fetch = await page.evaluate(
            "[window.boltwatchRun.readyMs, window.boltwatchRun.fetchMs]"
        )
        times.append(float(ready))
        fetches.append(float(fetch))
    return times


def summary(times: list[float]) -> str:
    if not times:
        return "none"
    p50, p95 = np.percentile(times, [50, 95])
    return f"n={len(times)} p50 {p50:.0f} ms, p95 {p95:.0f} ms, max {max(times):.0f} ms"


async def browse(
    url: str, runs: list[int], per_phase: int, browsers: int, line: Line, browser_nice: int
) -> dict[str, tuple[list[float], list[float]]]:
    """The phases (see the module docstring): per phase, each open's time to ready and the
    part of it that was the page's answer."""
    from playwright.async_api import async_playwright

    results: dict[str, tuple[list[float], list[float]]] = {}
    async with async_playwright() as playwright:
        browser = await playwright.chromium.launch(
            executable_path=str(_niced_chromium(line.folder, browser_nice)), args=CHROMIUM_ARGS
        )
        pages = []
        for _ in range(browsers):
            context = await browser.new_context(viewport={"width": 1280, "height": 1000})
            page = await context.new_page()
            await page.goto(url)
            await page.wait_for_selector("#station-st1", timeout=OPEN_TIMEOUT_MS)
            pages.append(page)
        fresh = iter(runs)

        def take(count: int) -> list[int]:
            return [next(fresh) for _ in range(count)]

        async def phase(name: str, shares: list[list[int]]) -> None:
            line.phase(name)
            fetches: list[float] = []
            browsing = zip(pages[: len(shares)], shares, strict=True)  # the first ones
            together = await asyncio.gather(
                *(open_runs(page, share, fetches) for page, share in browsing)
            )
            results[name] = ([t for times in together for t in times], fetches)

        for page in pages:  # each browser's first open (its scripts compiled): not counted
            await open_runs(page, take(1), [])
        quiet = take(per_phase)
        await phase("quiet", [quiet])
        await phase("quiet warm", [quiet])
        line.start_load()
        line.phase("load, nobody browsing")
        await asyncio.sleep(QUIET_LOAD_S)
        loaded = take(per_phase)
        await phase("load", [loaded])
        await phase(f"load, {browsers} browsers", [take(per_phase) for _ in pages])
        await phase("load warm", [loaded])
        line.phase("end")
        await browser.close()
    return results


def _niced_chromium(folder: Path, nice: int) -> Path:
    """Debian's chromium at ``nice`` (a browser on another machine takes no CPU from the
    line server's services; 0: as it is)."""
    if nice == 0:
        return CHROMIUM
    wrapper = folder / "chromium-niced"
    wrapper.write_text(f'#!/bin/sh\nexec nice -n {nice} {CHROMIUM} "$@"\n')
    wrapper.chmod(0o755)
    return wrapper


class Line:
    """The line server's processes, the load, and what is measured of them by phase."""

    def __init__(self, folder: Path, stations: int, samples: int, runs: int) -> None:
        self.folder = folder
        port = free_tcp_port()
        self.endpoint = f"tcp/127.0.0.1:{port}"
        base = _station_base(folder, port)
        self.paths = derive_stations(base, stations + 1, folder / "stations")
        st1 = self.paths[0]
        started = time.perf_counter()
        recordings = record_runs(folder / "pre", runs, samples, station_file=st1)
        with ResultsStore(store_target(recordings, None)) as store:
            files = station_recordings(recordings, ["st1"])
            fill_from_recordings(store, files, {}, "line-server", time.time_ns)
        print(f"{runs} runs of {samples} samples recorded in {time.perf_counter() - started:.0f} s")
        self.files = [str(p) for p in self.paths]
        self.processes: list[subprocess.Popen[bytes]] = []
        self.heard = RecorderHeard(listening=True)
        self.lag_ms: dict[str, list[float]] = {}
        self.missing: dict[str, int] = {}
        self.cpu: dict[str, tuple[float, float]] = {}
        self._phase = "start"
        self.generator: subprocess.Popen[bytes] | None = None
        self.page_port = free_tcp_port()
        self.board = BoardProbe(f"http://127.0.0.1:{self.page_port}/board.json")

    def start(self) -> None:
        serve_ = self.processes.append
        serve_(serve(["router", "--listen", self.endpoint], self.folder / "router.log"))
        self.recorder = serve(
            ["recorder", "--config", *self.files, "--no-rerun"], self.folder / "recorder.log"
        )
        serve_(self.recorder)
        listen = f"127.0.0.1:{self.page_port}"
        self.dashboard = serve(
            ["dashboard", "--config", *self.files, "--listen", listen],
            self.folder / "dashboard.log",
        )
        serve_(self.dashboard)
        self.session = zenoh.open(zenoh_config("client", [self.endpoint]))
        self.subscriber = self.session.declare_subscriber(channels.RECORDER.key("*"), self._stats)
        expected = {(load_station(p).station_id, "recorder") for p in self.paths}
        wait_alive(self.session, expected, self.processes, self.folder)
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(self.board.url, timeout=5).read()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)
        threading.Thread(target=self.board.run, daemon=True).start()
        self._cpu_at = (time.monotonic(), cpu_s(self.recorder), cpu_s(self.dashboard))

    def _stats(self, sample: zenoh.Sample) -> None:
        """Each station's RecorderStats (once a second): its lag's maximum, by phase."""
        self.heard.on_stats(sample)
        with self.heard.lock:
            self.missing[self._phase] = sum(self.heard.missing.values())
            self.lag_ms.setdefault(self._phase, []).extend(self.heard.lag_max_ms)
            self.heard.lag_max_ms.clear()

    def start_load(self) -> None:
        with (self.folder / "generator.log").open("wb") as out:
            self.generator = subprocess.Popen(
                [sys.executable, str(REPO / "tests/benchmarks/bench_line.py"), "--generate",
                 self.endpoint, "--seconds", "3600", *self.files[1:]],
                cwd=REPO, stdout=out, stderr=subprocess.STDOUT,
            )  # fmt: skip
        self.processes.append(self.generator)
        time.sleep(3.0)  # the load is on before anything is measured

    def phase(self, name: str) -> None:
        """A new phase: the CPU of the one before kept (recorder, page, a core's share)."""
        now = (time.monotonic(), cpu_s(self.recorder), cpu_s(self.dashboard))
        wall = now[0] - self._cpu_at[0]
        if wall > 0:
            recorder_s, page_s = now[1] - self._cpu_at[1], now[2] - self._cpu_at[2]
            self.cpu[self._phase] = (recorder_s / wall, page_s / wall)
        self._cpu_at = now
        self._phase = name
        self.board.phase = name

    def stop(self) -> None:
        self.board.stop.set()
        self.subscriber.undeclare()
        self.session.close()
        for process in reversed(self.processes):
            stop_process(process, grace_s=10.0)


def _station_base(folder: Path, port: int) -> Path:
    from tests.support.station_files import write_station

    return write_station(folder, zenoh_port=port, replacements=EDGE_PROGRAM)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, default=20, help="synthetic stations (load)")
    parser.add_argument("--samples", type=int, default=3000, help="samples a run opened")
    parser.add_argument("--per-phase", type=int, default=10, help="runs opened a phase a browser")
    parser.add_argument("--browsers", type=int, default=4, help="browsers at once at load")
    parser.add_argument(
        "--browser-nice",
        type=int,
        default=19,
        help="chromium's nice value (default 19: as if on another machine; 0: beside the line)",
    )
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    args = parser.parse_args(argv)
    runs = args.per_phase * (2 + args.browsers) + args.browsers
    with tempfile.TemporaryDirectory(prefix="bench-run-view-") as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        line = Line(folder, args.stations, args.samples, runs)
        try:
            line.start()
            url = f"http://127.0.0.1:{line.page_port}/"
            runs_ = list(range(1, runs + 1))
            results = asyncio.run(
                browse(url, runs_, args.per_phase, args.browsers, line, args.browser_nice)
            )
        finally:
            line.stop()
        generator = (folder / "generator.log").read_text().strip()
    print(f"N={args.stations} synthetic stations (+ st1), runs of {args.samples} samples")
    print("time to ready in the browser (click -> charts drawn, frame begun) [of it the page's")
    print("answer: asked -> received and parsed]:")
    for phase, (times, fetches) in results.items():
        print(f"  {phase}: {summary(times)} [{summary(fetches)}]")
    print("/board.json answer while browsing:")
    for phase, times in line.board.times_ms.items():
        print(f"  {phase}: {summary(times)}")
    print("recorder lag (each station's per-second max), samples missing, CPU in cores:")
    for phase in [*line.board.times_ms]:
        lag = line.lag_ms.get(phase, [])
        worst = f"p99 {np.percentile(lag, 99):.0f} ms, max {max(lag):.0f} ms" if lag else "-"
        cpu = line.cpu.get(phase)
        cores = f", CPU recorder {cpu[0]:.2f} page {cpu[1]:.2f}" if cpu else ""
        print(f"  {phase}: lag {worst}, missing {line.missing.get(phase, 0)}{cores}")
    print(f"  generator: {generator}")
    load = results["load"][0]
    p95 = float(np.percentile(load, 95))
    met = p95 <= GOAL_P95_MS
    verdict = "met" if met else "MISSED"
    print(
        f"goal (load, one browser, cold: p95 <= {GOAL_P95_MS:.0f} ms): {verdict} "
        f"({p95:.0f} ms; median {statistics.median(load):.0f})"
    )
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
