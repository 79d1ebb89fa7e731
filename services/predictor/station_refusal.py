"""One station, one predictor: a second one for a station is refused at start.

Two predictors deciding for one station would each stop its tool on their
own rules. Every predictor (the line's, ``boltwatch serve predictor``, and a
station's edge predictor in its acquisition) holds the liveliness token
``boltwatch/<station>/health/predictor``; a predictor about to start asks
the line for those tokens first.
"""

from __future__ import annotations

from collections.abc import Iterable

import zenoh

from shared import keys
from shared.errors import ConfigError

#: how long to ask the line whether another predictor already serves a station
PEER_CHECK_TIMEOUT_S = 1.0


def refuse_stations_served_elsewhere(session: zenoh.Session, station_ids: Iterable[str]) -> None:
    """ConfigError naming the stations of ``station_ids`` that already have a predictor."""
    served_elsewhere = set()
    replies = session.liveliness().get(
        keys.health_key("*", "predictor"), timeout=PEER_CHECK_TIMEOUT_S
    )
    for reply in replies:
        if reply.ok is not None:
            station_id, _ = keys.split_key(str(reply.ok.key_expr))
            served_elsewhere.add(station_id)
    clash = sorted(served_elsewhere & set(station_ids))
    if clash:
        raise ConfigError(
            f"station(s) {', '.join(clash)} already have a predictor on the line "
            f"({keys.health_key(clash[0], 'predictor')} is alive); "
            "two predictors must not decide for one station"
        )
