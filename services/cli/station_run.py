"""One ``boltwatch up``: bring a simulated station up, run tightenings, report.

Watches the station from its own zenoh client session: liveliness tokens for
readiness, ``runs`` for the table, ``bus`` for the acquisition's counters.
"""

from __future__ import annotations

import logging
import sys
import time
from pathlib import Path

import zenoh

from services.cli import run_table
from services.cli.station_supervisor import ManagedProcess, StationSupervisor
from shared import keys
from shared.codec import decode
from shared.config import LoadedStation, Program
from shared.errors import BoltwatchError, TransportError
from shared.messages import BusStats, RunSummary
from shared.zenoh_session import open_from, zenoh_config

LOG = logging.getLogger(__name__)

SERVICES = ("recorder", "predictor", "acquisition")
STOP_ORDER = ("rig", "acquisition", "predictor", "recorder", "router")
SUMMARY_WAIT_S = 5.0
RECORDER_DRAIN_S = 1.0


class ServiceDiedError(BoltwatchError):
    """A station process ended while it should have been running."""


class StationRun:
    def __init__(
        self,
        station: LoadedStation,
        program: Program,
        runs: int,
        log_dir: Path,
        startup_timeout_s: float,
    ) -> None:
        self.station = station
        self.program = program
        self.runs = runs
        self.startup_timeout_s = startup_timeout_s
        self.supervisor = StationSupervisor(station.path, log_dir)
        self.summaries: list[RunSummary] = []
        self.bus_stats: BusStats | None = None
        self.started_s = time.time()
        self._session: zenoh.Session | None = None
        self._stopped = False

    # -- the whole thing -----------------------------------------------------------------

    def run(self) -> int:
        station_id = self.station.station_id
        router_endpoint = self.station.config.zenoh.connect[0]
        print(
            f"boltwatch up: station {station_id}, program {self.program.id} "
            f"({self.program.name}), {self.runs} runs"
        )
        print(f"logs: {self.supervisor.log_dir}")
        self.supervisor.start("router", ["--listen", router_endpoint])
        self._session = self._open_watch_session(router_endpoint)
        subscriber = self._session.declare_subscriber(
            keys.station_key(station_id, "*"), zenoh.handlers.FifoChannel(10000)
        )
        for service in SERVICES:
            self.supervisor.start(service)
        self._wait_until_alive()
        print(f"services up after {time.time() - self.started_s:.1f} s; tightening...\n")
        print(run_table.header())
        rig = self.supervisor.start(
            "rig", ["--runs", str(self.runs), "--program", str(self.program.id)]
        )
        rig_done_at: float | None = None
        while len(self.summaries) < self.runs:
            self._drain(subscriber)
            self._check_alive(expected_exits={"rig"})
            if rig_done_at is None and rig.exit_code() is not None:
                if rig.exit_code() != 0:
                    raise ServiceDiedError(self._death_note(rig))
                rig_done_at = time.monotonic()
            if rig_done_at is not None and time.monotonic() - rig_done_at > SUMMARY_WAIT_S:
                print(
                    f"only {len(self.summaries)} of {self.runs} run summaries arrived",
                    file=sys.stderr,
                )
                break
            time.sleep(0.02)
        time.sleep(RECORDER_DRAIN_S)
        self._drain(subscriber)
        subscriber.undeclare()
        self.stop_everything()
        self.report()
        return 0 if len(self.summaries) == self.runs else 1

    # -- pieces --------------------------------------------------------------------------

    def _open_watch_session(self, endpoint: str) -> zenoh.Session:
        router = self.supervisor.find("router")
        deadline = time.monotonic() + self.startup_timeout_s
        while True:
            try:
                return open_from(zenoh_config("client", [endpoint], connect_timeout_ms=500))
            except TransportError:
                if router.exit_code() is not None:
                    raise ServiceDiedError(self._death_note(router)) from None
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)

    def _wait_until_alive(self) -> None:
        assert self._session is not None
        station_id = self.station.station_id
        deadline = time.monotonic() + self.startup_timeout_s
        missing = set(SERVICES)
        while missing:
            self._check_alive(expected_exits=set())
            for reply in self._session.liveliness().get(keys.health_key(station_id, "*")):
                if reply.ok is not None:
                    missing.discard(str(reply.ok.key_expr).rsplit("/", 1)[-1])
            if time.monotonic() > deadline:
                raise ServiceDiedError(
                    f"not alive after {self.startup_timeout_s:.0f} s: {', '.join(sorted(missing))}"
                    f" (logs in {self.supervisor.log_dir})"
                )
            if missing:
                time.sleep(0.2)

    def _drain(self, subscriber: zenoh.Subscriber) -> None:
        while (sample := subscriber.try_recv()) is not None:
            topic = str(sample.key_expr).rsplit("/", 1)[-1]
            try:
                if topic == keys.RUNS:
                    summary = decode(RunSummary, sample.payload.to_bytes())
                    self.summaries.append(summary)
                    print(run_table.row(summary), flush=True)
                elif topic == keys.BUS:
                    self.bus_stats = decode(BusStats, sample.payload.to_bytes())
            except BoltwatchError as err:
                LOG.warning("unreadable %s message: %s", topic, err)

    def _check_alive(self, expected_exits: set[str]) -> None:
        if self._stopped:
            return
        for managed in self.supervisor.unexpected_exits(expected_exits):
            raise ServiceDiedError(self._death_note(managed))

    def _death_note(self, managed: ManagedProcess) -> str:
        return (
            f"{managed.name} exited with status {managed.exit_code()}; its log "
            f"({managed.log_path}) ends with:\n{managed.log_tail()}"
        )

    def stop_everything(self) -> None:
        if self._stopped:
            return
        self._stopped = True
        self.supervisor.stop_all(order=STOP_ORDER)
        if self._session is not None:
            self._session.close()
            self._session = None

    # -- the report ----------------------------------------------------------------------

    def report(self) -> None:
        print()
        if self.summaries:
            print(run_table.header())
            for summary in self.summaries:
                print(run_table.row(summary))
            print(run_table.totals(self.summaries))
        if self.bus_stats is not None:
            stats = self.bus_stats
            print(
                f"CAN: {stats.frames} frames, {stats.samples} samples, "
                f"{stats.missed_samples} missed in {stats.counter_gaps} gaps, "
                f"{stats.unknown_ids + stats.wrong_length + stats.decode_errors} bad frames, "
                f"{stats.stop_commands} stop commands sent"
            )
        recordings = sorted(
            path
            for path in self.station.recordings_folder.rglob("*.mcap")
            if path.stat().st_mtime >= self.started_s
        )
        print(f"recordings: {self.station.recordings_folder}")
        for path in recordings:
            print(f"  {path.relative_to(self.station.recordings_folder)}")
        print(f"logs: {self.supervisor.log_dir}")
        print(f"took {time.time() - self.started_s:.1f} s")
