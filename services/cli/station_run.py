"""One ``boltwatch up``: bring simulated stations up, run tightenings, report.

One station (the default) or a line of N (``--stations N``): one router, ONE
recorder serving every station file, and per station an acquisition and a
rig. A station decides where its ``[predictor] placement`` says: in its
acquisition (``edge``, the default) or in ONE line predictor serving every
station placed on the line. Watches the line from its own zenoh client
session: liveliness tokens for readiness, ``tool`` and ``runs`` for the
table (a summary counts only for a run seen starting on the tool channel,
once: :mod:`services.cli.run_tally`), ``results`` for its OK/NOK column (a
run's result is published just before its summary), ``bus`` for each
acquisition's counters.

With ``controller="openprotocol"`` (one station) the rig is an Open Protocol
controller on TCP and the bridge (``serve openprotocol``) stands in for the
acquisition and the predictor; ``openprotocol`` (``BridgeStats``) gives the
counters of the report's last lines.

A multi-spindle station's ``--runs`` are cycles: it waits for a summary of
every spindle's run of each, shows each run's spindle, and counts the cycles'
common results (``cycles``) in the totals.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import zenoh

from services.cli import run_table
from services.cli.run_tally import RunTally
from services.cli.station_supervisor import ManagedProcess, StationSupervisor
from services.cli.unrecorded_runs import unrecorded_note, unrecorded_runs
from shared.config import LoadedStation, Program
from shared.contract import (
    BridgeStats,
    BusStats,
    CycleResult,
    RunSummary,
    TighteningResult,
    ToolState,
    channels,
    decode,
    keys,
)
from shared.errors import BoltwatchError, TransportError
from shared.runtime import open_from, zenoh_config

LOG = logging.getLogger(__name__)

#: every service whose liveliness token each station must show before the rigs start
#: (an edge predictor's token comes from the station's acquisition), per kind of controller
SERVICES = {
    "can": ("recorder", "predictor", "acquisition"),
    "openprotocol": ("recorder", "openprotocol"),
}
SUMMARY_WAIT_S = 5.0
RECORDER_DRAIN_S = 1.0
#: above this many files the report counts recordings per station instead of listing them
LISTED_RECORDINGS = 20


class ServiceDiedError(BoltwatchError):
    """A station process ended while it should have been running."""


class StationRun:
    def __init__(
        self,
        stations: LoadedStation | Sequence[LoadedStation],
        program: Program,
        runs: int,
        log_dir: Path,
        startup_timeout_s: float,
        controller: str = "can",
    ) -> None:
        self.controller = controller
        self.stations = [stations] if isinstance(stations, LoadedStation) else list(stations)
        self.station = self.stations[0]
        self.program = program
        self.runs = runs
        self.startup_timeout_s = startup_timeout_s
        self.line = len(self.stations) > 1
        #: a multi-spindle station's spindles: each of ``runs`` is a cycle of a run each
        self.spindles = self.station.config.station.spindles
        self.expected_runs = runs * self.spindles
        self.supervisor = StationSupervisor([s.path for s in self.stations], log_dir)
        self.tally = RunTally(s.station_id for s in self.stations)
        self.bus_stats: dict[str, BusStats] = {}
        self.bridge_stats: dict[str, BridgeStats] = {}
        #: (station, run id) -> the run's result (its OK/NOK), as heard on its results key
        self.results: dict[tuple[str, int], TighteningResult] = {}
        #: (station, sync id) -> a multi-spindle cycle's common result
        self.cycles: dict[tuple[str, int], CycleResult] = {}
        self.started_s = time.time()
        self._session: zenoh.Session | None = None
        self._stopped = False
        #: runs summarised with no run file (after the report): up's exit is then not 0
        self.unrecorded: list[RunSummary] = []

    def process_name(self, service: str, station_id: str) -> str:
        """``rig`` for the one station of ``up``; ``rig-st2`` on a line."""
        return f"{service}-{station_id}" if self.line else service

    @property
    def summaries(self) -> dict[str, list[RunSummary]]:
        """The counted summaries of each station (runs seen starting, once each)."""
        return self.tally.summaries

    @property
    def station_ids(self) -> list[str]:
        return [s.station_id for s in self.stations]

    def stop_order(self) -> list[list[str]]:
        """The tools first, the recorder last (so that the recording holds everything)."""
        per_station = [
            [self.process_name(service, station_id) for station_id in self.station_ids]
            for service in ("rig", "acquisition", "openprotocol")
        ]
        return [*per_station, ["predictor"], ["recorder"], ["router"]]

    @property
    def line_predicted(self) -> list[LoadedStation]:
        """The stations that decide in the line's predictor (placement ``line``)."""
        return [s for s in self.stations if s.config.predictor.placement == "line"]

    # -- the whole thing -----------------------------------------------------------------

    def run(self) -> int:
        router_endpoint = self.station.config.zenoh.connect[0]
        self._print_banner()
        self.supervisor.start("router", ["--listen", router_endpoint])
        self._session = self._open_watch_session(router_endpoint)
        subscribers = [
            self._session.declare_subscriber(
                keys.station_key("*", topic), zenoh.handlers.FifoChannel(10000)
            )
            for topic in (
                channels.TOOL.topic,
                channels.RESULTS.topic,
                channels.RUNS.topic,
                channels.CYCLES.topic,
                channels.BUS.topic,
                channels.OPENPROTOCOL.topic,
            )  # a run's start and its result before its summary
        ]
        self.supervisor.start("recorder")
        if self.line_predicted:
            self.supervisor.start("predictor", config_paths=[s.path for s in self.line_predicted])
        station_service = "openprotocol" if self.controller == "openprotocol" else "acquisition"
        for station in self.stations:
            name = self.process_name(station_service, station.station_id)
            self.supervisor.start(station_service, name=name, config_paths=[station.path])
        self._wait_until_alive()
        print(f"services up after {time.time() - self.started_s:.1f} s; tightening...\n")
        print(run_table.header(self.line, self.multi_spindle))
        rig_args = ["--runs", str(self.runs), "--program", str(self.program.id)]
        if self.controller == "openprotocol":
            rig_args += ["--controller", "openprotocol", "--wait-for-integrator"]
        rigs = [
            self.supervisor.start(
                "rig",
                rig_args,
                name=self.process_name("rig", station.station_id),
                config_paths=[station.path],
            )
            for station in self.stations
        ]
        rig_names = {rig.name for rig in rigs}
        rigs_done_at: float | None = None
        while not self._every_station_has_its_runs():
            for subscriber in subscribers:
                self._drain(subscriber)
            self._check_alive(expected_exits=rig_names)
            for rig in rigs:
                if rig.exit_code() not in (None, 0):
                    raise ServiceDiedError(self._death_note(rig))
            if rigs_done_at is None and all(rig.exit_code() is not None for rig in rigs):
                rigs_done_at = time.monotonic()
            if rigs_done_at is not None and time.monotonic() - rigs_done_at > SUMMARY_WAIT_S:
                print(f"only {self._count_note()} run summaries arrived", file=sys.stderr)
                break
            time.sleep(0.02)
        time.sleep(RECORDER_DRAIN_S)
        for subscriber in subscribers:
            self._drain(subscriber)
            subscriber.undeclare()
        self.stop_everything()
        self.report()
        return 0 if self._every_station_has_its_runs() and not self.unrecorded else 1

    @property
    def multi_spindle(self) -> bool:
        return self.spindles > 1

    def _every_station_has_its_runs(self) -> bool:
        return all(len(runs) >= self.expected_runs for runs in self.summaries.values())

    def _count_note(self) -> str:
        if not self.line:
            return f"{len(self.summaries[self.station.station_id])} of {self.expected_runs}"
        return ", ".join(
            f"{station_id} {len(runs)} of {self.expected_runs}"
            for station_id, runs in self.summaries.items()
        )

    def _print_banner(self) -> None:
        program = f"program {self.program.id} ({self.program.name})"
        if self.line:
            ids = self.station_ids
            print(
                f"boltwatch up: {len(ids)} stations {ids[0]}..{ids[-1]}, {program}, "
                f"{self.runs} runs each"
            )
            print(f"station files: {self.station.path.parent}")
        elif self.multi_spindle:
            print(
                f"boltwatch up: station {self.station.station_id} of {self.spindles} spindles, "
                f"{program}, {self.runs} cycles ({self.expected_runs} runs)"
            )
        else:
            print(f"boltwatch up: station {self.station.station_id}, {program}, {self.runs} runs")
        print(f"logs: {self.supervisor.log_dir}")

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
        deadline = time.monotonic() + self.startup_timeout_s
        missing = {
            (station_id, service)
            for station_id in self.station_ids
            for service in SERVICES[self.controller]
        }
        while missing:
            self._check_alive(expected_exits=set())
            for reply in self._session.liveliness().get(keys.health_key("*", "*")):
                if reply.ok is not None:
                    station_id, tail = keys.split_key(str(reply.ok.key_expr))
                    missing.discard((station_id, tail.rsplit("/", 1)[-1]))
            if time.monotonic() > deadline:
                names = sorted(
                    service if not self.line else f"{service} of {station_id}"
                    for station_id, service in missing
                )
                raise ServiceDiedError(
                    f"not alive after {self.startup_timeout_s:.0f} s: {', '.join(names)}"
                    f" (logs in {self.supervisor.log_dir})"
                )
            if missing:
                time.sleep(0.2)

    def _drain(self, subscriber: zenoh.Subscriber) -> None:
        while (sample := subscriber.try_recv()) is not None:
            try:
                station_id, topic = keys.split_key(str(sample.key_expr))
            except ValueError:
                continue
            if station_id not in self.summaries:
                continue  # another station on the same router: not ours to report
            try:
                self._heard(station_id, topic, sample.payload.to_bytes())
            except BoltwatchError as err:
                LOG.warning("unreadable %s message: %s", topic, err)

    def _heard(self, station_id: str, topic: str, payload: bytes) -> None:
        """One message of a station ``up`` watches, on ``topic``."""
        if topic == channels.TOOL.topic:
            self.tally.tool_state(station_id, decode(ToolState, payload))
        elif topic == channels.RESULTS.topic:
            result = decode(TighteningResult, payload)
            if result.station == station_id:
                self.results[(station_id, result.run_id)] = result
        elif topic == channels.CYCLES.topic:
            cycle = decode(CycleResult, payload)
            if cycle.station == station_id:
                self.cycles[(station_id, cycle.sync_id)] = cycle
        elif topic == channels.RUNS.topic:
            summary = decode(RunSummary, payload)
            if self.tally.summary(station_id, summary):
                print(self._row(summary), flush=True)
        elif topic == channels.BUS.topic:
            self.bus_stats[station_id] = decode(BusStats, payload)
        elif topic == channels.OPENPROTOCOL.topic:
            self.bridge_stats[station_id] = decode(BridgeStats, payload)

    def _row(self, summary: RunSummary) -> str:
        return run_table.row(
            summary,
            self.line,
            self.results.get((summary.station, summary.run_id)),
            self.multi_spindle,
        )

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
        self.supervisor.stop_all(order=self.stop_order())
        if self._session is not None:
            self._session.close()
            self._session = None

    # -- the report ----------------------------------------------------------------------

    def report(self) -> None:
        print()
        every_summary = [s for runs in self.summaries.values() for s in runs]
        if every_summary:
            print(run_table.header(self.line, self.multi_spindle))
            for summary in every_summary:
                print(self._row(summary))
            results = [
                result
                for s in every_summary
                if (result := self.results.get((s.station, s.run_id))) is not None
            ]
            print(run_table.totals(every_summary, results, list(self.cycles.values())))
        left_out = self.tally.note()
        if left_out is not None:
            print(left_out)
        for station_id in self.station_ids:
            stats = self.bus_stats.get(station_id)
            if stats is not None:
                label = f"CAN {station_id}" if self.line else "CAN"
                print(
                    f"{label}: {stats.frames} frames, {stats.samples} samples, "
                    f"{stats.missed_samples} missed in {stats.counter_gaps} gaps, "
                    f"{stats.unknown_ids + stats.wrong_length + stats.decode_errors} bad frames, "
                    f"{stats.stop_commands} stop commands sent"
                )
            bridge = self.bridge_stats.get(station_id)
            if bridge is not None:
                print(run_table.bridge_line(bridge))
        self._report_recordings()
        self.unrecorded = unrecorded_runs(
            self.station.recordings_folder, every_summary, self.started_s
        )
        if self.unrecorded:
            recorder_log = self.supervisor.log_dir / "recorder.log"
            note = unrecorded_note(self.unrecorded, len(every_summary), recorder_log)
            print(note, file=sys.stderr)
        print(f"logs: {self.supervisor.log_dir}")
        print(f"took {time.time() - self.started_s:.1f} s")

    def _report_recordings(self) -> None:
        folder = self.station.recordings_folder
        recordings = sorted(
            path for path in folder.rglob("*.mcap") if path.stat().st_mtime >= self.started_s
        )
        print(f"recordings: {folder}")
        if len(recordings) <= LISTED_RECORDINGS:
            for path in recordings:
                print(f"  {path.relative_to(folder)}")
            return
        for station_id in self.station_ids:
            count = sum(1 for p in recordings if p.relative_to(folder).parts[0] == station_id)
            print(f"  {station_id}/: {count} files")
