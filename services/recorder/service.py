"""``boltwatch serve recorder``: everything of its stations into MCAP files.

One zenoh session, one subscriber per station it serves on
``boltwatch/<st>/**`` (:class:`~services.recorder.live.line_inbox.LineInbox`: its
callback keeps each
message, the service's worker thread files them in batches every
:data:`TAKE_INTERVAL_S`). The worker also flushes files every half flush
interval, even when the line is quiet, and once a second publishes
:class:`~shared.contract.messages.RecorderStats` per station. On SIGTERM the
subscriber is undeclared, what it received is filed and every file
finished, so it is readable without recovery.

One process serves several stations (``--config A.toml B.toml``): each served station
gets its metadata from its own file, its own ``wear`` queryable and its own health
token; they share the recordings folder and the ``[recorder]`` settings (an error when
the files disagree). One recorder holds a station: a second one is refused at start
(:mod:`services.recorder.station_holder`); the one that holds it finishes the run files
a crash left unfinished (:func:`~shared.recordings.mcap.finish_unfinished`). A station
with no file is not its station: in a plant each line's recorder records its own line's
stations, and the subscription never asks the router for the others (no other line's
sample crosses to this line for it). No payload stops it: what it refuses
(:mod:`shared.recordings.received`) is recorded raw and counted in the station's
``RecorderStats.bad_payloads``. Every TighteningResult it files feeds the quality alert
(:mod:`services.recorder.quality_watch`, on ``quality/alert``) and the results store
(:mod:`services.recorder.results_watch`), every RunSummary the wear ledger
(``wear/alert``), every part scan the station's last part, which it answers on
``boltwatch/<st>/part`` (:mod:`services.recorder.last_parts`); a view-only recorder keeps
none of them. With a ``[retention]`` rule,
a thread of its own deletes the recordings the policy lets go
(:mod:`services.recorder.retention_watch`; the worker only tells it, at each tick, which
files it has open).

Beside each run's MCAP a Rerun ``.rrd`` is written (``--no-rerun``: not);
``--rerun-serve`` / ``--rerun-web`` also stream every run to a live viewer
(:class:`shared.recordings.rerun.rerun_sink.RerunLive`); ``--foxglove-port`` serves
every message it files as a Foxglove WebSocket too
(:class:`services.recorder.foxglove_live.foxglove_server.FoxgloveLive`). ``--view-only`` makes a
second recorder a live view beside the line's one: it keeps no wear ledger,
answers no wear query, publishes no RecorderStats and holds the health token
``viewer``, so nothing on the line mistakes it for the recorder. Rerun failing never stops
the MCAP recording: it is logged and the recorder goes on without it.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import socket
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import zenoh

from services.recorder.last_parts import LastParts
from services.recorder.live.line_inbox import LineInbox, Message
from services.recorder.live.recorder import Recorder
from services.recorder.live.recorder_health import RecorderHealth
from services.recorder.live.run_files import StationFiles
from services.recorder.live.sample_batches import BatchSamples
from services.recorder.live.spool_filing import SpoolFiling
from services.recorder.live.spool_keeper import SpoolKeeper
from services.recorder.live_views import rerun_options, start_foxglove, start_rerun_live
from services.recorder.quality_watch import QualityWatch
from services.recorder.results_watch import ResultsWatch
from services.recorder.retention_watch import RetentionWatch
from services.recorder.served_stations import limits_of, served_stations
from services.recorder.station_holder import (
    recordings_folder_held,
    refuse_stations_recorded_elsewhere,
)
from services.recorder.wear_queryable import wear_replier
from services.recorder.wear_watch import WearWatch
from shared.config import AnyStation, load_any_line
from shared.contract import (
    MAX_TEXT_CHARS,
    QualityAlert,
    RecorderStats,
    SpoolAck,
    WearAlert,
    WearForecast,
    channels,
    encode,
    keys,
    parse_seq_attachment,
)
from shared.recordings import OTHER_STATION, FileMetadata, Received, classify
from shared.recordings.mcap import finish_unfinished
from shared.results import station_store
from shared.retention import retention_scopes
from shared.runtime import ServiceSkeleton, Stop
from shared.wear import StationLimits, joint_names, ledger_path

if TYPE_CHECKING:
    from services.recorder.foxglove_live.foxglove_server import FoxgloveLive

LOG = logging.getLogger(__name__)

STATS_PERIOD_S = 1.0
#: how often what a station's spool sends again is acknowledged while it comes (else with
#: the stats, once a second)
REFILING_ACK_S = 0.2
#: how often the worker takes what the inbox received (a batch of 250 messages
#: on 50 stations): MCAP log times are taken on arrival; lag (RecorderStats) is
#: measured when a batch is filed, so it includes the wait in the inbox
TAKE_INTERVAL_S = 0.005
#: how often the files of newly filed results are flushed, and the results stored
RESULTS_FLUSH_S = 0.5
#: health role of a ``--view-only`` recorder (a live view, not the line's recorder)
VIEWER = "viewer"
_BUS_STATS = channels.BUS.schema_name
_SAMPLE = channels.SAMPLES.schema_name
_BATCH = channels.SAMPLE_BATCHES.schema_name
_SPOOL = channels.SPOOL.schema_name
_PART = channels.PART.schema_name


class RecorderService:
    """The recorder wired to the zenoh session of a :class:`ServiceSkeleton`."""

    def __init__(
        self,
        loaded: AnyStation | Sequence[AnyStation],
        skeleton: ServiceSkeleton,
        rerun_files: bool = True,
        rerun_live_url: str | None = None,
        view_only: bool = False,
        foxglove: FoxgloveLive | None = None,
    ) -> None:
        """``view_only``: a live view beside the line's recorder (``--view-only``). Its
        subscriber, queryables and health tokens are declared through ``skeleton``, which
        undeclares them when it closes. ``foxglove``: the live Foxglove server, given
        every message as it is filed (its owner stops it)."""
        stations = served_stations(loaded)
        first = stations[0]
        session = self._session = skeleton.session
        self._tick_s = first.config.recorder.flush_interval_s / 2
        rerun = rerun_options(rerun_files, rerun_live_url)
        metadata = FileMetadata(stations)
        self.station_ids = metadata.station_ids
        self._sensor_ranges = {station.station_id: station.sensor_range for station in stations}
        self.recorder = Recorder(first.recordings_folder, limits_of(first), metadata, rerun)
        #: where each served station is: plant, line, name (results, RecorderStats)
        self._places = {station.station_id: station.config.station.place for station in stations}
        self.health = RecorderHealth(self.station_ids, self._places)
        self._batches = BatchSamples()
        self._ledger_file = ledger_path(first.recordings_folder)
        #: with the ledger's path, which ledger a wear reply comes from (a plant has several)
        self._host = socket.gethostname()
        self.view_only = view_only
        self.foxglove = foxglove
        self.wear: WearWatch | None = None
        self.quality: QualityWatch | None = None
        self.results: ResultsWatch | None = None
        self.retention: RetentionWatch | None = None
        #: the last part scanned at each station (a view keeps none, answers none)
        self.last_parts: LastParts | None = None
        #: what the line's recorder filed of the stations' spools (a view acknowledges nothing)
        self.spooling = (
            None
            if view_only
            else SpoolFiling(
                SpoolKeeper(first.recordings_folder),
                self.recorder,
                self._file_received,
                self._deferred,
            )
        )
        if not view_only:
            self.last_parts = LastParts(first.recordings_folder, self.station_ids)
            settings = {station.station_id: station.config.quality for station in stations}
            self.quality = QualityWatch(settings, self._publish_alert)
            self.wear = WearWatch(
                self._ledger_file,
                first.config.recorder.wear_service_threshold,
                self._publish_alert,
                StationLimits(stations).of,
                first.config.recorder.wear_forecast_days,
            )
            self.results = ResultsWatch(
                station_store(first),
                first.recordings_folder,
                self._places,
                self._host,
            )
            (scope,) = retention_scopes(stations)  # one folder, one policy: served_stations
            if scope.policy.deletes:
                self.retention = RetentionWatch(scope)
        self._inbox = LineInbox(session, [station_keys(station) for station in self.station_ids])
        skeleton.on_stop(Stop.INPUT, self._inbox.close)
        for station in [] if view_only else self.station_ids:
            skeleton.queryable(
                keys.station_key(station, keys.WEAR),
                wear_replier(self._ledger_file, self._host, station, joint_names(stations)),
            )
            if self.last_parts is not None:
                skeleton.queryable(channels.PART.key(station), self.last_parts.replier(station))
        for station in self.station_ids:
            skeleton.health_token(station, VIEWER if view_only else "recorder")
        LOG.info(
            "recording %s into %s (its station files)",
            ", ".join(station_keys(station) for station in self.station_ids),
            first.recordings_folder,
        )

    def wake(self) -> None:
        """Make :meth:`work` look at its stop flag now."""
        self._inbox.wake()

    def work(self, stop: threading.Event) -> None:
        """Record until ``stop`` is set, then file what was received and finish every file."""
        next_tick = next_stats = next_ack = next_results = time.monotonic()
        try:
            while not stop.is_set():
                self._file(self._inbox.take(TAKE_INTERVAL_S))
                now = time.monotonic()
                spooling = self.spooling
                if spooling is not None and spooling.refiling and now >= next_ack:
                    # what a hole filed is acknowledged soon: a recorder killed meanwhile
                    # files again (twice) only what it filed since
                    self._acknowledge(time.time_ns())
                    next_ack = now + REFILING_ACK_S
                if self.results is not None and now >= next_results:
                    self._release_results(time.time_ns())
                    next_results = now + RESULTS_FLUSH_S
                if now >= next_tick:
                    self._tick()
                    next_tick = now + self._tick_s
                if now >= next_stats and not self.view_only:
                    self._acknowledge(time.time_ns())
                    self._publish_stats(time.time_ns())
                    next_stats = now + STATS_PERIOD_S
            self._file(self._inbox.take(0))  # a receive thread waiting for room gets it
            self._inbox.close()
            self._file(self._inbox.take(0))
            self._acknowledge(time.time_ns())  # what is in the files now
        finally:
            self._inbox.close()
            if self._inbox.after_close:
                LOG.warning("not recorded, arrived while stopping: %d", self._inbox.after_close)
            if self.wear is not None:
                self.wear.close()
            if self.last_parts is not None:
                self.last_parts.save()
            if self.retention is not None:
                self.retention.close()
            closed = self.recorder.close()
            if self.results is not None:
                self.results.close()  # after the files are finished
            LOG.info("recorder stopped: %d messages, %d files", self.recorder.messages, len(closed))

    def _tick(self) -> None:
        """Every half flush interval: flush and close what is due, tell the retention which
        files are open, the wear ledger's timers, save the stations' last parts."""
        self.recorder.tick(time.time_ns())
        if self.retention is not None:
            self.retention.open_files(self.recorder.open_paths())
        if self.wear is not None:
            self.wear.tick(time.time_ns())
        if self.last_parts is not None:
            self.last_parts.save()

    def stats(self, now_ns: int) -> list[RecorderStats]:
        """RecorderStats of every station now (starts the next lag window)."""
        recorder, wear, results, retention = self.recorder, self.wear, self.results, self.retention
        write_errors = recorder.write_errors + (wear.ledger_errors if wear else 0)
        ledger_error = wear.last_ledger_error if wear else None
        last_error = (
            recorder.last_write_error
            or (f"wear ledger: {ledger_error}" if ledger_error else None)
            or (results.last_error if results else None)
            or (retention.last_error if retention else None)
        )
        if last_error is not None:
            last_error = last_error[:MAX_TEXT_CHARS]  # a long path must not make it unreadable
        return self.health.report(
            now_ns,
            write_errors,
            last_error,
            recorder.recording_ok,
            refused_summaries=wear.refused if wear else None,
            waiting_summaries=wear.waiting if wear else 0,
            waiting_results=results.waiting if results else 0,
            quality_alerts=self.quality.active if self.quality else None,
            wear_forecasts=wear.forecasts.soon if wear and wear.forecasts else None,
            recordings_deleted=retention.deleted if retention else None,
            recordings_kept_unstored=retention.kept_not_stored if retention else None,
        )

    def _file(self, messages: list[Message]) -> None:
        filed_ns = time.time_ns()  # the lag counts the wait in the inbox too
        for key, payload, received_ns, attachment in messages:
            self._handle(key, payload, received_ns, filed_ns, attachment)

    def _handle(
        self, key: str, payload: bytes, now_ns: int, filed_ns: int, attachment: bytes | None = None
    ) -> None:
        """File one message received at ``now_ns`` (its MCAP log time) at ``filed_ns``; one a
        station's spool numbered (``attachment``) goes where its order says."""
        mark = parse_seq_attachment(attachment)
        live_key = keys.live_key_of(key)
        again = live_key is not None and mark is not None and mark.again
        if again and self.spooling is None:
            return  # a live view: what a spool sends again is for the line's recorder
        if mark is not None and mark.again != again:
            mark = None  # a mark that does not fit its key: not numbered (an again/ key: raw)
        filed_key = live_key if again and live_key is not None else key
        received = classify(filed_key, payload, now_ns, self._sensor_ranges)
        spooling = self.spooling
        if spooling is None or received.station == OTHER_STATION:
            self._file_received(received, filed_ns)
        elif mark is None:
            self._file_received(received, filed_ns, spooling.unnumbered_files(received.station))
        else:
            spooling.file(received, mark, filed_ns)

    def _file_received(
        self, received: Received, filed_ns: int, hole: StationFiles | None = None
    ) -> None:
        """File into the station's live files, or a hole's (``hole``: sent again, neither
        lag nor a live view's business)."""
        if received.schema_name == _BATCH and received.message is not None:
            self._file_batch(received, filed_ns, hole)
            return
        self._file_one(received, filed_ns, hole)

    def _file_one(
        self, received: Received, filed_ns: int, hole: StationFiles | None = None
    ) -> None:
        """File one message (a batch's event too) into its run's file and its counts."""
        now_ns = received.log_time_ns
        recording = self.recorder.write(received, hole)
        if self.foxglove is not None and hole is None:
            self.foxglove.log(received)
        if hole is not None and received.schema_name == _SAMPLE:
            self.health.refiled(received.station, 1)
        if received.station != OTHER_STATION and hole is None:
            is_sample = received.schema_name == _SAMPLE
            sample_time_ns = (
                received.publish_time_ns if is_sample and received.message is not None else None
            )
            self.health.written(
                received.station, filed_ns, sample_time_ns, is_sample, not received.decodable
            )
            if received.schema_name == _BUS_STATS and received.message is not None:
                bus = received.message
                self.health.bus_stats(received.station, bus.samples, bus.started_ns)
        if received.message is None:
            return
        if self.spooling is not None and received.schema_name == _SPOOL:
            self.spooling.on_stats(received.message)
        self._feed(received, recording, now_ns)

    def _feed(self, received: Received, recording: Path | None, now_ns: int) -> None:
        """A filed result or summary to the quality alert, the results store and the wear
        ledger (``recording``: the file it went into)."""
        schema, message = received.schema_name, received.message
        if schema == channels.RESULTS.schema_name:
            if self.quality is not None:
                self.quality.on_result(message)
            if self.results is not None:
                self.results.on_result(message, recording, now_ns)
        elif schema == channels.CYCLES.schema_name:
            if self.results is not None:
                self.results.on_cycle(message)
        elif schema == channels.RUNS.schema_name:
            if self.results is not None:
                self.results.on_summary(message)
            if self.wear is not None:
                self.wear.on_summary(message, now_ns)
        elif schema == channels.TOOL_DATA.schema_name and self.wear is not None:
            self.wear.on_tool_data(message, now_ns)
        elif schema == _PART and self.last_parts is not None:
            self.last_parts.on_scan(message, received.station)

    def _deferred(self, received: Received) -> None:
        """A live message a hole of its station's spool will file later: a run's summary is
        counted in the wear ledger now (it counts a run once: again when filed, nothing)."""
        if received.schema_name == channels.RUNS.schema_name and received.message is not None:
            if self.results is not None:
                self.results.on_summary(received.message)
            if self.wear is not None:
                self.wear.on_summary(received.message, received.log_time_ns)

    def _file_batch(self, batch: Received, filed_ns: int, hole: StationFiles | None) -> None:
        """Each sample of a batch, then its events and intensities, as if each had come alone
        (a refused batch is filed raw by :meth:`_file_one`: its samples are not received, so
        they count as missing)."""
        samples = self._batches.samples(batch)
        self.recorder.write_samples(batch.station, samples, hole)
        if hole is not None:
            self.health.refiled(batch.station, len(samples))
        else:
            times_ns = [sample.publish_time_ns for sample in samples]
            self.health.samples_written(batch.station, filed_ns, times_ns)
            if self.foxglove is not None:
                for sample in samples:
                    self.foxglove.log(sample)
        for found in self._batches.found(batch):
            self._file_one(found, filed_ns, hole)

    def _release_results(self, now_ns: int) -> None:
        """Flush the files of the results filed since the last time; then they go to the
        results store (a result stored is in a file on disk)."""
        assert self.results is not None
        stations = self.results.unflushed_stations()
        if not stations:
            return
        for station in stations:
            self.recorder.flush(station, now_ns)  # failing: the store keeps the result anyway
        self.results.release()

    def _acknowledge(self, now_ns: int) -> None:
        """Flush the spooling stations' files; acknowledge what they hold."""
        if self.spooling is not None:
            self.spooling.acknowledge(now_ns, self._publish_ack)

    def _publish_ack(self, ack: SpoolAck) -> None:
        """To the station only: a put this session also heard would come back to the inbox."""
        try:
            self._session.put(
                channels.SPOOL_ACK.key(ack.station),
                encode(ack),
                allowed_destination=zenoh.Locality.REMOTE,
            )
        except zenoh.ZError as err:  # session closing: the station sends it again
            LOG.debug("spool acknowledgement of %s not published: %s", ack.station, err)

    def _publish_stats(self, now_ns: int) -> None:
        """Put each station's RecorderStats for everyone but this recorder (not recorded)."""
        for stats in self.stats(now_ns):
            try:
                self._session.put(
                    channels.RECORDER.key(stats.station),
                    encode(stats),
                    allowed_destination=zenoh.Locality.REMOTE,
                )
            except zenoh.ZError as err:  # session closing
                LOG.debug("recorder stats of %s not published: %s", stats.station, err)

    def _publish_alert(self, alert: WearAlert | WearForecast | QualityAlert) -> None:
        """Put the alert for the line and record it here: a put this session also heard
        would come back through the inbox on this very thread, which waits when the
        inbox is full, for room only this thread makes."""
        key = channels.of_message(alert).key(alert.station)
        payload = encode(alert)
        self._session.put(
            key,
            payload,
            congestion_control=zenoh.CongestionControl.BLOCK,
            allowed_destination=zenoh.Locality.REMOTE,
        )
        now_ns = time.time_ns()
        self._handle(key, payload, now_ns, now_ns)


def station_keys(station: str) -> str:
    """Everything of one station: ``boltwatch/<st>/**``."""
    return keys.station_key(station, "**")


def main(args: argparse.Namespace) -> int:
    loaded = load_any_line(args.config)  # serve recorder: one or more files, always a list
    served_stations(loaded)  # bad combinations fail before zenoh is opened
    folder = loaded[0].make_recordings_folder()  # and a folder that can never be made
    view_only = getattr(args, "view_only", False)
    with contextlib.ExitStack() as held:
        if not view_only:
            held.enter_context(recordings_folder_held(folder))  # a second recorder: refused
        return _serve(args, loaded, folder, view_only)


def _serve(
    args: argparse.Namespace, loaded: Sequence[AnyStation], folder: Path, view_only: bool
) -> int:
    """The recorder's process, the recordings folder held (a view: not)."""
    with ServiceSkeleton(VIEWER if view_only else "recorder") as skeleton:
        # listening before the router is reached: a Foxglove app may connect first
        foxglove = start_foxglove(args, [station.station_id for station in loaded])
        if foxglove is not None:
            skeleton.on_stop(Stop.DEVICE, foxglove.close)
        session = skeleton.open_session(loaded[0].config.zenoh)
        if not view_only:
            refuse_stations_recorded_elsewhere(
                session, [s.station_id for s in loaded], loaded[0].config.zenoh.lease_s
            )
            finish_unfinished(folder)  # what a crash left, before the results' catch-up reads
        live = start_rerun_live(args)
        if live is not None:
            skeleton.on_stop(Stop.DEVICE, live.close)
        service = RecorderService(
            loaded,
            skeleton,
            rerun_files=not getattr(args, "no_rerun", False),
            rerun_live_url=live.url if live is not None else None,
            view_only=view_only,
            foxglove=foxglove,
        )
        return skeleton.run(service.work, service.wake)
