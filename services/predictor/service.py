"""``boltwatch serve predictor``: the predictor core wired to zenoh, for one or more stations.

One process serves the stations named by ``--config FILE [FILE ...]`` and
only those: per served station it subscribes to ``boltwatch/<st>/samples``
and ``boltwatch/<st>/tool`` (never ``boltwatch/*/*``: another station's data
must never reach this process's decisions); each message is handled in its
zenoh callback, one at a time (:mod:`services.predictor.station_inbox`).
Each run is predicted with its own station's programs, force sensor, joint
constants and ``[predictor]`` section. Out, per station: ``events`` and ``intensity``
per stick-slip event, ``decision`` (REAL_TIME priority, express, blocking
congestion control: a stop must never be dropped), ``runs`` per run. One
liveliness token ``boltwatch/<st>/health/predictor`` per served station; a
station that already has a predictor on the line is refused at start-up, so
two predictors never both decide for one station.

No payload stops the service: what does not decode (bad JSON, nested too
deeply, too large, a wrong type, a value out of its bounds or an id wider
than the station's CAN signal) or names another station is counted as a bad
payload and logged once, then at most every 10 s. What it counted goes out
per station once a second as :class:`~shared.messages.PredictorStats` on
``boltwatch/<st>/predictor`` (:mod:`services.predictor.station_counts`).
"""

from __future__ import annotations

import argparse
import logging
import threading
import time
from collections import deque
from collections.abc import Sequence
from typing import Any

import zenoh

from services.predictor.active_run import ActiveRun, Outgoing
from services.predictor.served_station import ServedStation
from services.predictor.station_counts import StationCounts
from services.predictor.station_inbox import Inbox, InboxFactory, StationInbox
from shared import codec, keys
from shared.config import LoadedStation, load_line
from shared.config.line import stations_by_id
from shared.errors import ConfigError, InputError
from shared.log_limit import RateLimitedLog
from shared.messages import Intensity, Sample, StopDecision, ToolState
from shared.receive_threads import use_one_receive_thread
from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_session

LOG = logging.getLogger(__name__)

#: how long to ask the line whether another predictor already serves a station
PEER_CHECK_TIMEOUT_S = 1.0
#: run ids remembered per station: a ToolState starting one of them again is ignored
STARTED_RUNS_KEPT = 64
#: how often each served station's PredictorStats goes out
STATS_PERIOD_S = 1.0


class PredictorService:
    """Runs of the served stations, one :class:`ActiveRun` per (station, run id)."""

    def __init__(
        self,
        session: zenoh.Session,
        stations: LoadedStation | Sequence[LoadedStation],
        inbox: InboxFactory = StationInbox,
    ) -> None:
        served = [stations] if isinstance(stations, LoadedStation) else list(stations)
        self._session = session
        self._stations = {
            station_id: ServedStation(station)
            for station_id, station in stations_by_id(served).items()
        }
        self._refuse_stations_served_elsewhere()
        self._runs: dict[tuple[str, int], ActiveRun] = {}
        self._publishers: dict[tuple[str, str], Any] = {}
        self.counts = {station_id: StationCounts(station_id) for station_id in self._stations}
        self.started_ns = time.time_ns()
        self._log_bad_payload = RateLimitedLog(LOG)
        self._log_no_program = RateLimitedLog(LOG, logging.ERROR)
        self._log_unfinished = RateLimitedLog(LOG)
        self._started: dict[str, deque[int]] = {}  # per station, the run ids that started
        self._inbox: Inbox = inbox(session, list(self._stations), self.handle)
        self._tokens = [
            session.liveliness().declare_token(keys.health_key(station_id, "predictor"))
            for station_id in self._stations
        ]

    @property
    def station_ids(self) -> list[str]:
        return list(self._stations)

    @property
    def bad_payloads(self) -> int:
        """Payloads refused, every served station."""
        return sum(counts.bad_payloads for counts in self.counts.values())

    @property
    def dropped_samples(self) -> int:
        """Samples of no running run, every served station."""
        return sum(counts.samples_without_run for counts in self.counts.values())

    @property
    def unfinished_runs(self) -> int:
        """Runs whose end never arrived (a network outage), every served station."""
        return sum(counts.unfinished_runs for counts in self.counts.values())

    @property
    def repeated_runs(self) -> int:
        """Run ids that started again after they had started (ignored), every served station."""
        return sum(counts.repeated_runs for counts in self.counts.values())

    def _refuse_stations_served_elsewhere(self) -> None:
        served_elsewhere = set()
        replies = self._session.liveliness().get(
            keys.health_key("*", "predictor"), timeout=PEER_CHECK_TIMEOUT_S
        )
        for reply in replies:
            if reply.ok is not None:
                station_id, _ = keys.split_key(str(reply.ok.key_expr))
                served_elsewhere.add(station_id)
        clash = sorted(served_elsewhere & set(self._stations))
        if clash:
            raise ConfigError(
                f"station(s) {', '.join(clash)} already have a predictor on the line "
                f"({keys.health_key(clash[0], 'predictor')} is alive); "
                "two predictors must not decide for one station"
            )

    def close(self) -> None:
        self._inbox.close()
        for publisher in self._publishers.values():
            publisher.undeclare()
        self._publishers.clear()
        for token in self._tokens:
            token.undeclare()
        self._tokens.clear()

    def __enter__(self) -> PredictorService:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

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
            for counts in self.counts.values():
                stats = counts.stats(now_ns, self.started_ns)
                try:
                    self._session.put(
                        keys.station_key(stats.station, keys.PREDICTOR), codec.encode(stats)
                    )
                except zenoh.ZError as err:  # the session is closing
                    LOG.debug("predictor stats of %s not published: %s", stats.station, err)

    def handle(self, station_id: str, topic: str, payload: bytes) -> None:
        """Dispatch one message received on a served station's ``topic`` key."""
        served = self._stations.get(station_id)
        if served is None:  # cannot happen: the inbox only subscribes to served stations
            return
        try:
            if topic == keys.SAMPLES:
                sample = served.decode_sample(payload)
                if self._belongs(sample.station, station_id, topic):
                    self._on_sample(sample)
            elif topic == keys.TOOL:
                state = served.decode_tool_state(payload)
                if self._belongs(state.station, station_id, topic):
                    self._on_tool(served, state)
        except InputError as err:
            counts = self.counts[station_id]
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
        counts = self.counts[station_id]
        counts.bad_payloads += 1
        self._log_bad_payload(
            "ignored a %s message on %s that names station %s (#%d)",
            topic,
            keys.station_key(station_id, topic),
            station_in_payload,
            counts.bad_payloads,
        )
        return False

    def _on_tool(self, served: ServedStation, state: ToolState) -> None:
        run_key = (state.station, state.run_id)
        if state.state == "running":
            if run_key in self._runs:
                return
            started = self._started.setdefault(state.station, deque(maxlen=STARTED_RUNS_KEPT))
            if state.run_id in started:  # a run id starts once, however its state flips
                self.counts[state.station].repeated_runs += 1
                return
            started.append(state.run_id)
            self._forget_unfinished_runs(state.station)
            try:
                program = served.program(state.program_id)
            except KeyError as err:
                self._log_no_program(
                    "run %s: %s; not predicting this run", state.run_id, err.args[0]
                )
                return
            self._runs[run_key] = ActiveRun(state, program, served.settings(program))
            LOG.debug("%s run %s started (program %s)", state.station, state.run_id, program.id)
        elif state.state in ("done", "aborted"):
            run = self._runs.pop(run_key, None)
            if run is None:
                return
            summary = run.summary(state)
            self.counts[state.station].run_ended(run.core.input_report)
            self._publish(state.station, keys.RUNS, summary)
            LOG.info(
                "%s run %s %s: %d events, stop %s, error %s %%, %s",
                state.station,
                state.run_id,
                state.state,
                summary.events,
                summary.stop_reason,
                f"{summary.error_pct:.2f}" if summary.error_pct is not None else "-",
                run.core.input_report.as_dict(),
            )

    def _forget_unfinished_runs(self, station: str) -> None:
        """A new run of ``station`` starts: its older runs have ended, unheard (an outage)."""
        for run_key in [key for key in self._runs if key[0] == station]:
            run = self._runs.pop(run_key)
            counts = self.counts[station]
            counts.unfinished_runs += 1
            counts.run_ended(run.core.input_report)
            self._log_unfinished(
                "%s run %s: its end never arrived (network outage?); no summary, %s",
                station,
                run_key[1],
                run.core.input_report.as_dict(),
            )

    def _on_sample(self, sample: Sample) -> None:
        run = self._runs.get((sample.station, sample.run_id))
        if run is None:
            self.counts[sample.station].samples_without_run += 1
            return
        for message in run.on_sample(sample, time.time_ns()):
            self._send(sample.station, message)

    def _send(self, station: str, message: Outgoing) -> None:
        if isinstance(message, StopDecision):
            self._publish(station, keys.DECISION, message)
            LOG.info(
                "%s run %s: stop (%s) %s", station, message.run_id, message.reason, message.detail
            )
        elif isinstance(message, Intensity):
            self._publish(station, keys.INTENSITY, message)
        else:
            self._publish(station, keys.EVENTS, message)

    def _publish(self, station: str, topic: str, message: object) -> None:
        publisher = self._publishers.get((station, topic))
        if publisher is None:
            if topic == keys.DECISION:
                publisher = self._session.declare_publisher(
                    keys.station_key(station, topic),
                    priority=zenoh.Priority.REAL_TIME,
                    express=True,
                    congestion_control=zenoh.CongestionControl.BLOCK,
                )
            else:  # BLOCK too: zenoh's default DROP lost events under load, silently
                publisher = self._session.declare_publisher(
                    keys.station_key(station, topic),
                    congestion_control=zenoh.CongestionControl.BLOCK,
                )
            self._publishers[(station, topic)] = publisher
        publisher.put(codec.encode(message))


def main(args: argparse.Namespace) -> int:
    """Load every station file once, open one session, serve until a signal."""
    # One receive thread: callbacks never pass the GIL between two receive threads
    # (measured with bench_line_inbox.py, variant callback-rx1; figures in the README).
    use_one_receive_thread()
    stations = load_line(args.config)
    with (
        open_session(stations[0].config.zenoh) as session,
        PredictorService(session, stations) as service,
    ):
        return ServiceRunner("predictor", service.work, service.wake).run()
