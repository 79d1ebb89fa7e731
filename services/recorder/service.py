"""``boltwatch serve recorder``: everything on ``boltwatch/**`` into MCAP files.

One zenoh session, one subscriber on :data:`shared.keys.EVERYTHING` with a
deep FIFO channel, read with a blocking ``recv()`` in the service's worker
thread (:class:`shared.service_runtime.ServiceRunner`). Two session-local
keys drive it without leaving the process: ``boltwatch/_local/wake`` (stop
now) and ``boltwatch/_local/tick`` (put every half flush interval so files
are flushed even when the line is quiet). On SIGTERM the channel is drained
and every file finished, so it is readable without recovery.

Beside each run's MCAP a Rerun ``.rrd`` is written (``--no-rerun``: not);
``--rerun-serve`` / ``--rerun-web`` also stream every run to a live viewer
(:class:`services.recorder.rerun_sink.RerunLive`). Rerun failing never stops
the MCAP recording: it is logged and the recorder goes on without it.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import threading
import time
from typing import TYPE_CHECKING

import zenoh

from services.recorder.file_metadata import FileMetadata
from services.recorder.incoming import LOCAL_PREFIX, classify
from services.recorder.recorder import Recorder
from services.recorder.run_files import FileLimits
from services.recorder.wear_ledger import WearLedger, ledger_path
from services.recorder.wear_watch import ALERT_TOPIC, WearAlert, WearWatch
from shared import keys
from shared.codec import encode
from shared.config import LoadedStation, load_station
from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_session

if TYPE_CHECKING:
    from services.recorder.rerun_sink import RerunLive, RerunOptions

LOG = logging.getLogger(__name__)

WAKE_KEY = f"{LOCAL_PREFIX}wake"
TICK_KEY = f"{LOCAL_PREFIX}tick"
CHANNEL_DEPTH = 100_000  # 100 s of samples at 1 kHz
_DRAIN_LIMIT = CHANNEL_DEPTH


def limits_of(loaded: LoadedStation) -> FileLimits:
    section = loaded.config.recorder
    return FileLimits(
        flush_interval_ns=round(section.flush_interval_s * 1e9),
        max_file_bytes=section.max_file_bytes,
        max_file_duration_ns=round(section.max_file_duration_s * 1e9),
    )


class RecorderService:
    """The recorder wired to one zenoh session (which the caller opens and closes)."""

    def __init__(
        self,
        loaded: LoadedStation,
        session: zenoh.Session,
        rerun_files: bool = True,
        rerun_live_url: str | None = None,
    ) -> None:
        self._session = session
        self._tick_s = loaded.config.recorder.flush_interval_s / 2
        rerun = rerun_options(rerun_live_url) if rerun_files else None
        self.recorder = Recorder(
            loaded.recordings_folder, limits_of(loaded), FileMetadata(loaded), rerun
        )
        self._station_id = loaded.station_id
        self._ledger_file = ledger_path(loaded.recordings_folder)
        self.wear = WearWatch(
            self._ledger_file, loaded.config.recorder.wear_service_threshold, self._publish_alert
        )
        self._subscriber = session.declare_subscriber(
            keys.EVERYTHING, zenoh.handlers.FifoChannel(CHANNEL_DEPTH)
        )
        self._queryable = session.declare_queryable(
            keys.station_key(loaded.station_id, keys.WEAR), self._reply_wear
        )
        self._token = session.liveliness().declare_token(
            keys.health_key(loaded.station_id, "recorder")
        )
        LOG.info("recording %s into %s", keys.EVERYTHING, loaded.recordings_folder)

    def wake(self) -> None:
        """Unblock ``recv()`` in :meth:`work` (a put that never leaves the process)."""
        self._local_put(WAKE_KEY)

    def work(self, stop: threading.Event) -> None:
        """Record until ``stop`` is set, then drain the channel and finish every file."""
        ticker = threading.Thread(
            target=self._tick_until, args=(stop,), name="recorder-tick", daemon=True
        )
        ticker.start()
        try:
            while not stop.is_set():
                self._handle(self._subscriber.recv())
            for _ in range(_DRAIN_LIMIT):
                sample = self._subscriber.try_recv()
                if sample is None:
                    break
                self._handle(sample)
        finally:
            self.wear.close()
            closed = self.recorder.close()
            LOG.info("recorder stopped: %d messages, %d files", self.recorder.messages, len(closed))
            ticker.join(self._tick_s + 1.0)

    def close(self) -> None:
        """Undeclare the subscriber and the health token; safe to call twice."""
        for entity in (self._token, self._queryable, self._subscriber):
            with contextlib.suppress(zenoh.ZError):
                entity.undeclare()

    def _handle(self, sample: zenoh.Sample) -> None:
        now_ns = time.time_ns()
        key = str(sample.key_expr)
        if key.startswith(LOCAL_PREFIX):
            if key == TICK_KEY:
                self.recorder.tick(now_ns)
            return
        received = classify(key, sample.payload.to_bytes(), now_ns)
        self.recorder.write(received)
        if received.schema_name == "boltwatch.RunSummary" and received.message is not None:
            self.wear.on_summary(received.message, now_ns)

    def _publish_alert(self, alert: WearAlert) -> None:
        self._session.put(keys.station_key(alert.station, ALERT_TOPIC), encode(alert))

    def _reply_wear(self, query: zenoh.Query) -> None:
        """``boltwatch/<station>/wear``: every tool's line of the ledger as one JSON object."""
        try:
            with WearLedger(self._ledger_file, read_only=True) as ledger:
                tools = [tool.to_dict() for tool in ledger.tools()]
        except Exception as err:  # a reply, never a dead queryable thread
            LOG.warning("wear query failed: %s", err)
            query.reply_err(str(err).encode())
            return
        reply = {"station": self._station_id, "ledger": str(self._ledger_file), "tools": tools}
        query.reply(query.key_expr, json.dumps(reply).encode())

    def _tick_until(self, stop: threading.Event) -> None:
        while not stop.wait(self._tick_s):
            self._local_put(TICK_KEY)

    def _local_put(self, key: str) -> None:
        try:
            self._session.put(key, b"", allowed_destination=zenoh.Locality.SESSION_LOCAL)
        except zenoh.ZError as err:  # session already closing
            LOG.debug("local put on %s failed: %s", key, err)


def rerun_options(live_url: str | None) -> RerunOptions | None:
    """Options of the per-run .rrd files; None (logged) when Rerun cannot be imported."""
    try:
        from services.recorder.rerun_sink import RerunOptions
    except ImportError:
        LOG.exception("Rerun is unusable; recording MCAP only")
        return None
    return RerunOptions(live_url=live_url)


def start_rerun_live(args: argparse.Namespace) -> RerunLive | None:
    """The live Rerun server (and web viewer) when asked for; None when off or failing."""
    web = bool(getattr(args, "rerun_web", False))
    if not (web or getattr(args, "rerun_serve", False)):
        return None
    try:
        from services.recorder.rerun_sink import RerunLive

        return RerunLive(args.rerun_port, args.rerun_web_port if web else None)
    except Exception:
        LOG.exception("cannot start the Rerun live view; recording goes on without it")
        return None


def main(args: argparse.Namespace) -> int:
    loaded = load_station(args.config[0])  # TODO(multi-station)
    session = open_session(loaded.config.zenoh)
    live = start_rerun_live(args)
    try:
        service = RecorderService(
            loaded,
            session,
            rerun_files=not getattr(args, "no_rerun", False),
            rerun_live_url=live.url if live is not None else None,
        )
        try:
            return ServiceRunner("recorder", service.work, service.wake).run()
        finally:
            service.close()
    finally:
        session.close()
        if live is not None:
            live.close()
