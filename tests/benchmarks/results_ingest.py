"""How fast results go into the results store, for ``bench_results_store.py``.

:func:`live_ingest`: as a user meets it. A real recorder (``RunningRecorder``:
a RecorderService in a thread of this process, its results store the one of
its station files, ``[recorder] results_database``) serving ``stations``
stations of a line hears their ``TighteningResult`` over real zenoh on
loopback, put by this process (one publisher a station, BLOCK, round robin)
at rates rising step by step; each step's results are new (run ids go on).
Per step: the rate the results were put at, the time until the last of them
is in the store (``ResultsStore.count`` polled from a connection of its
own), hence the rate sustained from the first put to the last stored, and
the largest backlog on the way: results put and not yet stored, and of those
the ones waiting in the recorder's memory for the writer
(``ResultsWatch.waiting``). Only results are put: a real station's run
brings its samples too, which the recorder files first (its own benchmarks).

:func:`add_rates`: ``ResultsStore.add`` alone, in batches of given sizes, a
transaction each: the store's raw rate, for reference.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import zenoh

from shared.config import LoadedStation, load_station
from shared.contract import encode, keys
from shared.results import (
    ResultsQuery,
    ResultsStore,
    StoreError,
    StoreTarget,
    store_target,
    stored_result,
)
from shared.runtime import zenoh_config
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    free_port,
    has_subscribers,
    wait_until,
    write_station_file,
)

#: how long the last results of a step may take to be stored before the step gives up
DRAIN_LIMIT_S = 120.0
POLL_S = 0.02


@dataclass(frozen=True)
class IngestStep:
    offered_per_s: float  # the rate asked for
    results: int
    put_s: float  # first put to last put
    stored_s: float  # first put to the last result in the store
    backlog_max: int  # put and not yet stored, at most
    waiting_max: int  # of them, in the recorder's memory for the writer, at most

    @property
    def put_per_s(self) -> float:
        return self.results / self.put_s

    @property
    def sustained_per_s(self) -> float:
        return self.results / self.stored_s

    def line(self) -> str:
        return (
            f"offered {self.offered_per_s:6.0f}/s: {self.results} results put at "
            f"{self.put_per_s:6.0f}/s, all stored after {self.stored_s:5.2f} s "
            f"(last {self.stored_s - self.put_s:4.2f} s after the last put): sustained "
            f"{self.sustained_per_s:6.0f}/s; backlog at most {self.backlog_max} "
            f"({self.waiting_max} waiting in the recorder's memory)"
        )


def station_files(folder: Path, stations: int, database: str | None) -> list[LoadedStation]:
    """``stations`` station files (``st01``... on line ``L1``), one recordings folder, the
    first listening on a free loopback port."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    recorder = {} if database is None else {"results_database": database}
    template = write_station_file(
        folder / "template.toml", folder / "recordings", listen=[endpoint], recorder=recorder
    ).read_text()
    loaded = []
    for n in range(1, stations + 1):
        path = folder / f"st{n:02d}.toml"
        path.write_text(template.replace('id = "st1"', f'id = "st{n:02d}"\nline = "L1"', 1))
        loaded.append(load_station(path))
    return loaded


class _Counter:
    """The store's row count, from a connection of its own (None until there is a store)."""

    def __init__(self, target: StoreTarget) -> None:
        self._target = target
        self._store: ResultsStore | None = None

    def opened(self) -> bool:
        """Whether the store is there (the recorder makes it as it starts)."""
        self.count()
        return self._store is not None

    def count(self) -> int:
        try:
            if self._store is None:
                self._store = ResultsStore(self._target, create=False)
            return self._store.count(ResultsQuery())
        except StoreError:
            return 0

    def close(self) -> None:
        if self._store is not None:
            self._store.close()


def live_ingest(
    folder: Path, database: str | None, stations: int, rates: Sequence[float], seconds: float
) -> list[IngestStep]:
    """One recorder into the store ``database`` (None: SQLite beside the recordings), the
    steps of ``rates`` (results a second, all stations together) for ``seconds`` each."""
    folder.mkdir(parents=True)
    loaded = station_files(folder, stations, database)
    first = loaded[0]
    counter = _Counter(store_target(first.recordings_folder, database))
    recorder = RunningRecorder(loaded)
    session = zenoh.open(zenoh_config("peer", connect=first.config.zenoh.listen))
    names = [station.station_id for station in loaded]
    publishers = [
        session.declare_publisher(
            keys.station_key(name, "results"), congestion_control=zenoh.CongestionControl.BLOCK
        )
        for name in names
    ]
    steps = []
    try:
        wait_until(lambda: all(has_subscribers(p) for p in publishers), "the recorder")
        wait_until(counter.opened, "the recorder's store", DRAIN_LIMIT_S)
        run_id = 0
        for rate in rates:
            total = max(stations, round(rate * seconds))
            steps.append(_step(recorder, counter, publishers, names, run_id, total, rate))
            run_id += total // stations + 1
    finally:
        for publisher in publishers:
            publisher.undeclare()
        session.close()
        recorder.finish()
        counter.close()
    return steps


def _step(
    recorder: RunningRecorder,
    counter: _Counter,
    publishers: list[zenoh.Publisher],
    names: list[str],
    first_run: int,
    total: int,
    rate: float,
) -> IngestStep:
    watch = recorder.service.results
    assert watch is not None
    before = counter.count()
    put = stored = 0
    backlog_max = waiting_max = 0
    done = threading.Event()

    def watch_store() -> None:  # the only user of the counter meanwhile
        nonlocal stored, backlog_max, waiting_max
        while not done.is_set():
            waiting_max = max(waiting_max, watch.waiting)
            stored = counter.count() - before
            backlog_max = max(backlog_max, put - stored)
            time.sleep(POLL_S)

    monitor = threading.Thread(target=watch_store, name="store-count")
    started = time.monotonic()
    monitor.start()
    try:
        for n in range(total):
            due = started + n / rate
            if (wait := due - time.monotonic()) > 0:
                time.sleep(wait)
            station = n % len(names)
            run_id = first_run + n // len(names) + 1
            result = factories.result(
                run_id,
                station=names[station],
                time_ns=time.time_ns(),
                part_id=f"L1-P{run_id // 5:07d}-{names[station]}",
            )
            publishers[station].put(encode(result))
            put += 1
        put_s = time.monotonic() - started
        deadline = time.monotonic() + DRAIN_LIMIT_S
        while stored < total:
            if time.monotonic() > deadline:
                raise AssertionError(f"not every result stored after {DRAIN_LIMIT_S} s")
            time.sleep(POLL_S / 4)
        stored_s = time.monotonic() - started
    finally:
        done.set()
        monitor.join()
    return IngestStep(rate, total, put_s, stored_s, backlog_max, waiting_max)


@dataclass(frozen=True)
class AddRate:
    batch: int
    results: int
    seconds: float

    def line(self) -> str:
        return (
            f"batches of {self.batch:4d}: {self.results / self.seconds:7.0f} results/s "
            f"({self.seconds / (self.results / self.batch) * 1e3:.2f} ms a batch)"
        )


def add_rates(target: StoreTarget, batches: Sequence[int], results: int) -> list[AddRate]:
    """``ResultsStore.add`` of ``results`` new results in batches of each size of
    ``batches`` (predictor results, no steps), into the store ``target``."""
    rates = []
    run_id = 0
    with ResultsStore(target) as store:
        for batch in batches:
            made = []
            for _ in range(results):
                run_id += 1
                result = factories.result(run_id, part_id=f"L1-P{run_id // 5:07d}")
                made.append(stored_result(result, "L1", "/srv/st1_run.mcap", "host", 0))
            started = time.perf_counter()
            for start in range(0, results, batch):
                store.add(made[start : start + batch])
            rates.append(AddRate(batch, results, time.perf_counter() - started))
    return rates
