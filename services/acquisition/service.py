"""``boltwatch serve acquisition``: wire the CAN bus and zenoh to :class:`Acquisition`.

Where the decision runs is the station file's ``[predictor] placement``:

- ``edge`` (the default): the station's predictor runs here, on the CAN
  thread (a :class:`~services.acquisition.decider.Decider` the CLI passes
  in: the predictor's ``EdgePredictor``); a sample that decides goes out as
  a ``StopCommand`` within the same call. Decisions on zenoh are then this
  process's own, published for the line; none is taken from zenoh (so a node
  on the network cannot stop this station's tool);
- ``line``: a ``boltwatch serve predictor`` elsewhere decides; this process
  subscribes ``boltwatch/<station>/decision`` (and ``/stage``, a final stage's
  commands) and turns each decision for the running run into a ``StopCommand``
  (a ``StageCommand``) straight from the zenoh callback (a bad payload is
  counted in ``BusStats.bad_decisions``, never raised into zenoh).

The CAN thread runs under ``SCHED_FIFO`` where allowed (:mod:`shared.runtime.realtime`)
and never waits on zenoh: samples, run states, bus counters and the
predictor's messages go through the station's queued publisher.
"""

from __future__ import annotations

import argparse
import logging
import threading
import time
from collections.abc import Callable

import zenoh

from services.acquisition.acquisition import Acquisition
from services.acquisition.decider import DeciderFactory
from services.acquisition.zenoh_outlet import ZenohOutlet
from shared.config import load_station
from shared.contract import StationDatabase, channels
from shared.errors import ConfigError
from shared.runtime import (
    STOP_PATH_PRIORITY,
    QueuedPublisher,
    ServiceSkeleton,
    Stop,
    open_bus,
    station_spool,
    use_realtime_priority,
)

LOG = logging.getLogger(__name__)

POLL_TIMEOUT_S = 0.05  # the stop flag is checked at least this often


def decision_handler(acquisition: Acquisition) -> Callable[[zenoh.Sample], None]:
    """The zenoh callback of ``boltwatch/<st>/decision``: into :meth:`Acquisition.decision`
    (placement line: a decision on the line becomes a ``StopCommand``)."""
    key = channels.DECISION.key(acquisition.station_id)

    def on_decision(sample: zenoh.Sample) -> None:
        acquisition.decision(sample.payload.to_bytes(), key)

    return on_decision


def stage_handler(acquisition: Acquisition) -> Callable[[zenoh.Sample], None]:
    """The zenoh callback of ``boltwatch/<st>/stage``: into :meth:`Acquisition.stage`
    (placement line: a final stage's command on the line becomes a CAN command)."""
    key = channels.STAGE.key(acquisition.station_id)

    def on_stage(sample: zenoh.Sample) -> None:
        acquisition.stage(sample.payload.to_bytes(), key)

    return on_stage


def main(args: argparse.Namespace, decider_factory: DeciderFactory | None = None) -> int:
    station = load_station(args.config)
    edge = station.config.predictor.placement == "edge"
    if edge and decider_factory is None:
        raise ConfigError(
            f"{station.path}: predictor.placement: 'edge' puts the predictor in the "
            "acquisition: start it with 'boltwatch serve acquisition'"
        )
    database = StationDatabase(station.dbc_path)
    station_id = station.station_id
    with ServiceSkeleton("acquisition") as skeleton:
        bus = skeleton.device(open_bus(station.config.can))
        # a spooling station starts without its router: the spool keeps what it measures
        wait = not station.config.spool.enabled
        session = skeleton.open_session(station.config.zenoh, wait_for_router=wait)
        publisher = QueuedPublisher(
            session,
            station_id,
            batch_samples=edge,
            spool=station_spool(station, "acquisition"),
            runs_at_once=station.config.station.spindles,
        )
        skeleton.on_stop(Stop.OUTPUT, publisher.close)
        outlet = ZenohOutlet(session, publisher)
        skeleton.on_stop(Stop.OUTPUT, outlet.close)  # the link first, then the queue's flush
        decider = None
        if edge and decider_factory is not None:
            decider = decider_factory(skeleton, station, publisher.publish)
            skeleton.on_stop(Stop.WORK, decider.close)
        acquisition = Acquisition(
            station_id,
            station.config.station.has_force_sensor,
            bus,
            database,
            outlet,
            unsent_samples=lambda: outlet.unsent_samples,
            decider=decider,
            stage_commands=station.config.can.tool_commands == "auto",
            spindles=station.config.station.spindles,
            spindle_id_stride=station.config.can.spindle_id_stride,
        )
        if not edge:
            skeleton.subscriber(channels.DECISION.key(station_id), decision_handler(acquisition))
            skeleton.subscriber(channels.STAGE.key(station_id), stage_handler(acquisition))
        skeleton.health_token(station_id, "acquisition")
        LOG.info(
            "acquisition of %s on %s:%s, decisions %s",
            station_id,
            station.config.can.interface,
            station.config.can.channel,
            "on this CAN thread (placement edge)" if edge else "from the line's predictor",
        )

        def last_bus_stats() -> None:
            outlet.bus_stats(acquisition.stats())
            LOG.info("acquisition stopped: %s", acquisition.stats())

        skeleton.on_stop(Stop.WORK, last_bus_stats)  # before the decider's close

        def work(stop: threading.Event) -> None:
            use_realtime_priority(STOP_PATH_PRIORITY, "acquisition CAN thread")
            next_stats = time.monotonic() + args.stats_interval_s
            while not stop.is_set():
                acquisition.poll(POLL_TIMEOUT_S)
                if time.monotonic() >= next_stats:
                    outlet.bus_stats(acquisition.stats())
                    next_stats += args.stats_interval_s

        return skeleton.run(work)
