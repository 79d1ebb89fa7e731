"""``boltwatch serve predictor``: the predictor core wired to zenoh.

One session, ONE subscriber on ``boltwatch/*/*`` (a FIFO channel of 10 000
messages, drained by a blocking ``recv()`` in the ServiceRunner's worker):
``samples`` go to the core of their run, ``tool`` marks run boundaries,
every other topic is ignored. Out: ``events`` and ``intensity`` per
stick-slip event, ``decision`` (REAL_TIME priority, express, blocking
congestion control: a stop must never be dropped), ``runs`` per run. The
liveliness token ``boltwatch/<station>/health/predictor`` says it is up.
To stop, ``wake`` puts a session-local message that unblocks ``recv()``.
"""

from __future__ import annotations

import argparse
import logging
import threading
import time
from typing import Any

import zenoh

from services.predictor.active_run import ActiveRun, Outgoing
from services.predictor.core import PredictorSettings
from shared import codec, keys
from shared.config import LoadedStation, load_station
from shared.errors import InputError
from shared.messages import Intensity, Sample, StopDecision, ToolState
from shared.model import JointConstants
from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_session

LOG = logging.getLogger(__name__)

WAKE_KEY = "boltwatch/_local/wake"
QUEUE_MESSAGES = 10_000


class PredictorService:
    """Runs of every station on the subscription, one :class:`ActiveRun` each."""

    def __init__(self, session: zenoh.Session, station: LoadedStation) -> None:
        self._session = session
        self._station = station
        self._constants = JointConstants.of(station.joint)
        self._runs: dict[tuple[str, int], ActiveRun] = {}
        self._publishers: dict[tuple[str, str], Any] = {}
        self.dropped_samples = 0
        self.bad_payloads = 0
        self._subscriber = session.declare_subscriber(
            keys.ALL_STATION_TOPICS, zenoh.handlers.FifoChannel(QUEUE_MESSAGES)
        )
        self._token = session.liveliness().declare_token(
            keys.health_key(station.station_id, "predictor")
        )

    def close(self) -> None:
        for publisher in self._publishers.values():
            publisher.undeclare()
        self._publishers.clear()
        self._token.undeclare()
        self._subscriber.undeclare()

    def __enter__(self) -> PredictorService:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def wake(self) -> None:
        """Unblock ``recv()`` without sending anything beyond this process."""
        self._session.put(WAKE_KEY, b"", allowed_destination=zenoh.Locality.SESSION_LOCAL)

    def work(self, stop: threading.Event) -> None:
        """The worker loop: receive, dispatch, until ``stop`` is set."""
        LOG.info("predictor up for station %s", self._station.station_id)
        while not stop.is_set():
            try:
                message = self._subscriber.recv()
            except zenoh.ZError:
                break  # the subscriber was closed
            self.handle(str(message.key_expr), message.payload.to_bytes())

    def handle(self, key: str, payload: bytes) -> None:
        """Dispatch one received message by the last chunk of its key."""
        topic = key.rsplit("/", 1)[-1]
        try:
            if topic == keys.SAMPLES:
                self._on_sample(codec.decode(Sample, payload))
            elif topic == keys.TOOL:
                self._on_tool(codec.decode(ToolState, payload))
        except InputError as err:
            self.bad_payloads += 1
            LOG.warning("ignored a bad %s payload: %s", topic, err)

    def _on_tool(self, state: ToolState) -> None:
        run_key = (state.station, state.run_id)
        if state.state == "running":
            if run_key in self._runs:
                return
            try:
                program = self._station.config.program(state.program_id)
            except KeyError as err:
                LOG.error("run %s: %s; not predicting this run", state.run_id, err.args[0])
                return
            config = self._station.config
            settings = PredictorSettings.of(
                program, config.predictor, config.station.has_force_sensor, self._constants
            )
            self._runs[run_key] = ActiveRun(state, program, settings)
            LOG.debug("run %s started (program %s)", state.run_id, program.id)
        elif state.state in ("done", "aborted"):
            run = self._runs.pop(run_key, None)
            if run is None:
                return
            summary = run.summary(state)
            self._publish(state.station, keys.RUNS, summary)
            LOG.info(
                "run %s %s: %d events, stop %s, error %s %%, %s",
                state.run_id,
                state.state,
                summary.events,
                summary.stop_reason,
                f"{summary.error_pct:.2f}" if summary.error_pct is not None else "-",
                run.core.input_report.as_dict(),
            )

    def _on_sample(self, sample: Sample) -> None:
        run = self._runs.get((sample.station, sample.run_id))
        if run is None:
            self.dropped_samples += 1
            return
        for message in run.on_sample(sample, time.time_ns()):
            self._send(sample.station, message)

    def _send(self, station: str, message: Outgoing) -> None:
        if isinstance(message, StopDecision):
            self._publish(station, keys.DECISION, message)
            LOG.info("run %s: stop (%s) %s", message.run_id, message.reason, message.detail)
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
            else:
                publisher = self._session.declare_publisher(keys.station_key(station, topic))
            self._publishers[(station, topic)] = publisher
        publisher.put(codec.encode(message))


def main(args: argparse.Namespace) -> int:
    """Load the station file once, open the session, serve until a signal."""
    station = load_station(args.config[0])  # TODO(multi-station)
    with (
        open_session(station.config.zenoh) as session,
        PredictorService(session, station) as service,
    ):
        return ServiceRunner("predictor", service.work, service.wake).run()
