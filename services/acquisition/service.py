"""``boltwatch serve acquisition``: wire the CAN bus and zenoh to :class:`Acquisition`.

Where the decision runs is the station file's ``[predictor] placement``:

- ``edge`` (the default): the station's predictor runs here, on the CAN
  thread (a :class:`~services.acquisition.decider.Decider` the CLI passes
  in: the predictor's ``EdgePredictor``); a sample that decides goes out as
  a ``StopCommand`` within the same call. Decisions on zenoh are then this
  process's own, published for the line; none is taken from zenoh (so a node
  on the network cannot stop this station's tool);
- ``line``: a ``boltwatch serve predictor`` elsewhere decides; this process
  subscribes ``boltwatch/<station>/decision`` and turns each decision for
  the running run into a ``StopCommand`` straight from the zenoh callback (a
  bad payload is counted in ``BusStats.bad_decisions``, never raised into
  zenoh).

The CAN thread runs under ``SCHED_FIFO`` where allowed (:mod:`shared.realtime`)
and never waits on zenoh: samples, run states, bus counters and the
predictor's messages go through the station's queued publisher.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import threading
import time

import zenoh

from services.acquisition.acquisition import Acquisition
from services.acquisition.decider import DeciderFactory
from services.acquisition.zenoh_outlet import ZenohOutlet
from shared import channels, keys
from shared.can_bus import open_bus
from shared.can_database import StationDatabase
from shared.config import load_station
from shared.errors import ConfigError
from shared.queued_publisher import QueuedPublisher
from shared.realtime import STOP_PATH_PRIORITY, use_realtime_priority
from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_session

LOG = logging.getLogger(__name__)

POLL_TIMEOUT_S = 0.05  # the stop flag is checked at least this often


def subscribe_decisions(session: zenoh.Session, acquisition: Acquisition) -> zenoh.Subscriber[None]:
    """``boltwatch/<st>/decision`` into :meth:`Acquisition.decision`, in zenoh's callback."""
    key = channels.DECISION.key(acquisition.station_id)

    def on_decision(sample: zenoh.Sample) -> None:
        acquisition.decision(sample.payload.to_bytes(), key)

    return session.declare_subscriber(key, on_decision)


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
    with contextlib.ExitStack() as resources:
        bus = resources.enter_context(open_bus(station.config.can))
        session = resources.enter_context(open_session(station.config.zenoh))
        publisher = QueuedPublisher(session, station_id, batch_samples=edge)
        resources.callback(publisher.close)
        outlet = ZenohOutlet(session, publisher)
        resources.callback(outlet.close)
        decider = None
        if edge and decider_factory is not None:
            decider = decider_factory(session, station, publisher.publish)
            resources.callback(decider.close)
        acquisition = Acquisition(
            station_id,
            station.config.station.has_force_sensor,
            bus,
            database,
            outlet,
            unsent_samples=lambda: outlet.unsent_samples,
            decider=decider,
        )
        if not edge:
            decisions = subscribe_decisions(session, acquisition)
            resources.callback(decisions.undeclare)
        token = session.liveliness().declare_token(keys.health_key(station_id, "acquisition"))
        resources.callback(token.undeclare)
        LOG.info(
            "acquisition of %s on %s:%s, decisions %s",
            station_id,
            station.config.can.interface,
            station.config.can.channel,
            "on this CAN thread (placement edge)" if edge else "from the line's predictor",
        )

        def work(stop: threading.Event) -> None:
            use_realtime_priority(STOP_PATH_PRIORITY, "acquisition CAN thread")
            next_stats = time.monotonic() + args.stats_interval_s
            while not stop.is_set():
                acquisition.poll(POLL_TIMEOUT_S)
                if time.monotonic() >= next_stats:
                    outlet.bus_stats(acquisition.stats())
                    next_stats += args.stats_interval_s

        status = ServiceRunner("acquisition", work).run()
        outlet.bus_stats(acquisition.stats())
        LOG.info("acquisition stopped: %s", acquisition.stats())
    return status
