"""``boltwatch serve openprotocol``: wire a controller's Open Protocol link to the station's zenoh.

Loads the station file once (its ``[openprotocol]`` section is required here:
without it, one line and exit status 2), opens the station's zenoh session,
declares ``boltwatch/<station>/health/openprotocol``, and runs the bridge
(:mod:`.bridge`) in the work thread. Everything goes out through the station's
queued publisher with samples in batches (as an edge station's acquisition
sends them: nothing on the line decides on a controller's samples); the
counters (:class:`~shared.contract.messages.BridgeStats`) once a second from a timer of
their own. On stop: the session ends with 0003, the last counters go out, the
queue is flushed, the token undeclared.

Each tightening is replayed through the stick-slip library after the fact
(:mod:`shared.stickslip.advisory_replay`), as ``boltwatch import`` does.
"""

from __future__ import annotations

import argparse
import logging
import threading

from services.openprotocol.bridge import OpenProtocolBridge
from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.published_ids import position_path
from shared.config import load_any_station
from shared.errors import ConfigError
from shared.runtime import QueuedPublisher, ServiceSkeleton, Stop, station_spool

LOG = logging.getLogger(__name__)


def main(args: argparse.Namespace) -> int:
    station = load_any_station(args.config)
    section = station.config.openprotocol
    if section is None:
        raise ConfigError(
            f"{station.path}: openprotocol: no [openprotocol] section: give the controller's "
            "host (and port, default 4545) to bridge it"
        )
    recordings = station.make_recordings_folder()
    station_id = station.station_id
    counts = BridgeCounts(station_id, f"{section.host}:{section.port}")
    with ServiceSkeleton("openprotocol") as skeleton:
        # a spooling station starts without its router: the spool keeps what it measures
        wait = not station.config.spool.enabled
        session = skeleton.open_session(station.config.zenoh, wait_for_router=wait)
        publisher = QueuedPublisher(
            session, station_id, batch_samples=True, spool=station_spool(station, "openprotocol")
        )
        skeleton.on_stop(Stop.OUTPUT, publisher.close)
        bridge = OpenProtocolBridge(
            station,
            section,
            publisher.publish,
            publisher.call,
            position_path(recordings, station_id),
            args.trace_timeout_s,
            counts,
        )
        stats_stop = threading.Event()

        def publish_stats() -> None:
            while not stats_stop.wait(args.stats_interval_s):
                publisher.publish(counts.stats())

        stats = threading.Thread(target=publish_stats, name="bridge-stats", daemon=True)
        stats.start()

        def last_stats() -> None:
            stats_stop.set()
            stats.join(timeout=5.0)
            publisher.publish(counts.stats())
            LOG.info("bridge stopped: %s", counts.stats())

        skeleton.on_stop(Stop.WORK, last_stats)
        skeleton.health_token(station_id, "openprotocol")
        LOG.info(
            "bridge of %s to the controller at %s:%d (watermark %d)",
            station_id,
            section.host,
            section.port,
            bridge.position.watermark,
        )
        return skeleton.run(bridge.work)
