"""``boltwatch serve predictor``: the predictor core wired to zenoh, for one or more stations.

One process serves the stations named by ``--config FILE [FILE ...]`` and
only those: per served station it subscribes to ``boltwatch/<st>/samples``,
``boltwatch/<st>/tool`` and ``boltwatch/<st>/part`` (never ``boltwatch/*/*``:
another station's data must never reach this process's decisions, nor
another station's part its results); each message is handled in its zenoh
callback, one at a time (:mod:`services.predictor.station_inbox`), so a part
scanned before a run's ``running`` is the part of that run. At start it asks
the line for each station's last part in the background
(:mod:`services.predictor.part_at_start`).
Each run is predicted with its own station's programs, force sensor, joint
constants and ``[predictor]`` section. Out, per station: ``events`` and ``intensity``
per stick-slip event, ``decision`` (REAL_TIME priority, express, blocking
congestion control: a stop must never be dropped), ``results`` and ``runs`` per
run. One liveliness token ``boltwatch/<st>/health/predictor`` per served station; a
station whose acquisition decides (``[predictor] placement = "edge"``, the
default) is refused at once, from its file, and a station that already has
a predictor on the line is refused at start-up, so two predictors never both
decide for one station (:mod:`services.predictor.station_refusal`).

Everything it puts for a station goes through that station's queued publisher
(:class:`~shared.runtime.QueuedPublisher`, the ``predictor`` source of the
station's spool, ``[spool]``): kept in ``<spool folder>/<st>-predictor.sqlite``
until the line's recorder has it, so a recorder that was down, or a cut
between this process and the recorder, loses none of its events, intensities,
decisions, results, summaries or counters. The callback that decides only
queues; the publisher's thread keeps and puts, in order.

No payload stops the service: what does not decode (bad JSON, nested too
deeply, too large, a wrong type, a value out of its bounds or an id wider
than the station's CAN signal) or names another station is counted as a bad
payload and logged once, then at most every 10 s. What it counted goes out
per station once a second as :class:`~shared.contract.messages.PredictorStats` on
``boltwatch/<st>/predictor`` (:mod:`services.predictor.station_counts`).
"""

from __future__ import annotations

import argparse
import logging
import threading
import time
from collections.abc import Sequence

from services.predictor.active_run import Outgoing
from services.predictor.part_at_start import PartAtStart
from services.predictor.served_station import ServedStation
from services.predictor.station_counts import StationCounts
from services.predictor.station_inbox import Inbox, InboxFactory, StationInbox
from services.predictor.station_refusal import (
    refuse_edge_stations,
    refuse_stations_served_elsewhere,
)
from services.predictor.station_runs import StationRuns
from shared.config import LoadedStation, load_line, stations_by_id
from shared.contract import Sample, StopDecision, ToolState, channels, keys
from shared.errors import InputError
from shared.runtime import (
    QueuedPublisher,
    RateLimitedLog,
    ServiceSkeleton,
    Stop,
    station_spool,
    use_one_receive_thread,
)

LOG = logging.getLogger(__name__)

#: how often each served station's PredictorStats goes out
STATS_PERIOD_S = 1.0
#: the source of a line predictor's messages in its stations' spools
SPOOL_SOURCE = "predictor"


class PredictorService:
    """Runs of the served stations, one :class:`ActiveRun` per (station, run id)."""

    def __init__(
        self,
        skeleton: ServiceSkeleton,
        stations: LoadedStation | Sequence[LoadedStation],
        inbox: InboxFactory = StationInbox,
    ) -> None:
        """Declares through ``skeleton`` (its session, inbox, publishers, health tokens),
        which undeclares them when it closes."""
        served = [stations] if isinstance(stations, LoadedStation) else list(stations)
        self._session = skeleton.session
        self._stations = {
            station_id: ServedStation(station)
            for station_id, station in stations_by_id(served).items()
        }
        refuse_stations_served_elsewhere(self._session, self._stations)
        self._runs = {
            station_id: StationRuns(served) for station_id, served in self._stations.items()
        }
        #: per station, its queued publisher (with the station's spool, source "predictor")
        self._publishers: dict[str, QueuedPublisher] = {}
        for station_id, served_station in self._stations.items():
            spool = station_spool(served_station.station, SPOOL_SOURCE)
            publisher = QueuedPublisher(self._session, station_id, spool=spool)
            skeleton.on_stop(Stop.OUTPUT, publisher.close)
            self._publishers[station_id] = publisher
        self.started_ns = time.time_ns()
        self._log_bad_payload = RateLimitedLog(LOG)
        self._inbox: Inbox = inbox(self._session, list(self._stations), self.handle)
        skeleton.on_stop(Stop.INPUT, self._inbox.close)
        # the part at each station until a scan is heard: asked of the line, never waited for
        self._part_at_start = PartAtStart(self._session, self._runs)
        skeleton.on_stop(Stop.INPUT, self._part_at_start.close)
        for station_id in self._stations:
            skeleton.health_token(station_id, "predictor")

    @property
    def station_ids(self) -> list[str]:
        return list(self._stations)

    def wake(self) -> None:
        """Unblock the worker's wait in :meth:`work`."""
        self._inbox.wake()

    def work(self, stop: threading.Event) -> None:
        """The worker: messages are handled by the inbox until ``stop`` is set; meanwhile a
        thread publishes each station's PredictorStats every :data:`STATS_PERIOD_S`."""
        LOG.info("predictor up for station(s) %s", ", ".join(self._stations))
        done = threading.Event()
        stats = threading.Thread(
            target=self._publish_stats_until, args=(stop, done), name="predictor-stats"
        )
        stats.start()
        try:
            self._inbox.serve(stop)
        finally:
            done.set()
            stats.join()

    def _publish_stats_until(self, stop: threading.Event, done: threading.Event) -> None:
        while not (stop.is_set() or done.wait(STATS_PERIOD_S)):
            now_ns = time.time_ns()
            for station_id, runs in self._runs.items():
                self._publishers[station_id].publish(runs.counts.stats(now_ns, self.started_ns))

    def handle(self, station_id: str, topic: str, payload: bytes) -> None:
        """Dispatch one message received on a served station's ``topic`` key."""
        runs = self._runs.get(station_id)
        if runs is None:  # cannot happen: the inbox only subscribes to served stations
            return
        served = runs.served
        try:
            if topic == channels.SAMPLES.topic:
                sample = served.decode_sample(payload)
                if self._belongs(sample.station, station_id, topic):
                    self._on_sample(runs, sample)
            elif topic == channels.TOOL.topic:
                state = served.decode_tool_state(payload)
                if self._belongs(state.station, station_id, topic):
                    self._on_tool(runs, state)
            elif topic == channels.PART.topic:
                scan = served.decode_part(payload)
                if self._belongs(scan.station, station_id, topic):
                    runs.on_part(scan)
        except InputError as err:
            counts = runs.counts
            counts.bad_payloads += 1
            self._log_bad_payload(
                "ignored a bad %s payload of %s (#%d): %s",
                topic,
                station_id,
                counts.bad_payloads,
                err,
            )

    def _belongs(self, station_in_payload: str, station_id: str, topic: str) -> bool:
        """A payload naming another station than its key is counted and ignored."""
        if station_in_payload == station_id:
            return True
        counts = self._runs[station_id].counts
        counts.bad_payloads += 1
        self._log_bad_payload(
            "ignored a %s message on %s that names station %s (#%d)",
            topic,
            keys.station_key(station_id, topic),
            station_in_payload,
            counts.bad_payloads,
        )
        return False

    def _on_tool(self, runs: StationRuns, state: ToolState) -> None:
        for message in runs.on_tool(state):  # a run's result and summary when it ended
            self._publish(state.station, message)

    def _on_sample(self, runs: StationRuns, sample: Sample) -> None:
        for message in runs.on_sample(sample, time.time_ns()):
            self._send(sample.station, message)

    @property
    def counts(self) -> dict[str, StationCounts]:
        """What each served station's predictor counted (its PredictorStats)."""
        return {station_id: runs.counts for station_id, runs in self._runs.items()}

    @property
    def part_ids(self) -> dict[str, str | None]:
        """The part at each served station: the last one scanned, else the line's at start
        (None: none known)."""
        return {station_id: runs.part_id for station_id, runs in self._runs.items()}

    @property
    def bad_payloads(self) -> int:
        """Payloads refused, every served station."""
        return sum(runs.counts.bad_payloads for runs in self._runs.values())

    @property
    def dropped_samples(self) -> int:
        """Samples of no running run, every served station."""
        return sum(runs.counts.samples_without_run for runs in self._runs.values())

    @property
    def unfinished_runs(self) -> int:
        """Runs whose end never arrived (a network outage), every served station."""
        return sum(runs.counts.unfinished_runs for runs in self._runs.values())

    @property
    def repeated_runs(self) -> int:
        """Run ids that started again after they had started (ignored), every served station."""
        return sum(runs.counts.repeated_runs for runs in self._runs.values())

    def _send(self, station: str, message: Outgoing) -> None:
        self._publish(station, message)
        if isinstance(message, StopDecision):
            LOG.info(
                "%s run %s: stop (%s) %s", station, message.run_id, message.reason, message.detail
            )

    def _publish(self, station: str, message: object) -> None:
        """``message`` on its channel of ``station``, through the station's queued publisher
        (the channel's options: decisions REAL_TIME and express; every channel BLOCK)."""
        self._publishers[station].publish(message)


def main(args: argparse.Namespace) -> int:
    """Load every station file once, open one session, serve until a signal."""
    # One receive thread: callbacks never pass the GIL between two receive threads
    # (measured with bench_line_inbox.py, variant callback-rx1: docs/explanation/design.md).
    use_one_receive_thread()
    stations = load_line(args.config)
    refuse_edge_stations(stations)  # an edge station's acquisition decides: refused at once
    with ServiceSkeleton("predictor") as skeleton:
        skeleton.open_session(stations[0].config.zenoh)
        service = PredictorService(skeleton, stations)
        return skeleton.run(service.work, service.wake)
