"""``boltwatch serve acquisition``: wire the CAN bus and zenoh to :class:`Acquisition`.

Subscribes ``boltwatch/<station>/decision`` and turns each decision for the
running run into a CAN ``StopCommand`` straight from the zenoh callback (the
shortest stop path; a bad payload is counted in ``BusStats.bad_decisions``,
never raised into zenoh); publishes samples, run states and bus counters.
"""

from __future__ import annotations

import argparse
import logging
import threading
import time

import zenoh

from services.acquisition.acquisition import Acquisition
from services.acquisition.zenoh_outlet import ZenohOutlet
from shared import keys
from shared.can_bus import open_bus
from shared.can_database import StationDatabase
from shared.config import load_station
from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_session

LOG = logging.getLogger(__name__)

POLL_TIMEOUT_S = 0.05  # the stop flag is checked at least this often


def subscribe_decisions(session: zenoh.Session, acquisition: Acquisition) -> zenoh.Subscriber[None]:
    """``boltwatch/<st>/decision`` into :meth:`Acquisition.decision`, in zenoh's callback."""
    key = keys.station_key(acquisition.station_id, keys.DECISION)

    def on_decision(sample: zenoh.Sample) -> None:
        acquisition.decision(sample.payload.to_bytes(), key)

    return session.declare_subscriber(key, on_decision)


def main(args: argparse.Namespace) -> int:
    station = load_station(args.config)
    database = StationDatabase(station.dbc_path)
    station_id = station.station_id
    with open_bus(station.config.can) as bus, open_session(station.config.zenoh) as session:
        outlet = ZenohOutlet(session, station_id)
        acquisition = Acquisition(
            station_id,
            station.config.station.has_force_sensor,
            bus,
            database,
            outlet,
            unsent_samples=lambda: outlet.unsent_samples,
        )

        decisions = subscribe_decisions(session, acquisition)
        token = session.liveliness().declare_token(keys.health_key(station_id, "acquisition"))
        LOG.info(
            "acquisition of %s on %s:%s",
            station_id,
            station.config.can.interface,
            station.config.can.channel,
        )

        def work(stop: threading.Event) -> None:
            next_stats = time.monotonic() + args.stats_interval_s
            while not stop.is_set():
                acquisition.poll(POLL_TIMEOUT_S)
                if time.monotonic() >= next_stats:
                    outlet.bus_stats(acquisition.stats())
                    next_stats += args.stats_interval_s

        status = ServiceRunner("acquisition", work).run()
        outlet.bus_stats(acquisition.stats())
        LOG.info("acquisition stopped: %s", acquisition.stats())
        decisions.undeclare()
        token.undeclare()
        outlet.close()
    return status
