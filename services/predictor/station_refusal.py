"""One station, one predictor: who decides is the station file's, a second one is refused.

Two predictors deciding for one station would each stop its tool on their
own rules. Who decides is said once, in the station file's ``[predictor]
placement``, and checked before anything else, whatever runs already:

- ``"edge"`` (the default): the station's acquisition decides, on its CAN
  thread (its edge predictor). ``boltwatch serve predictor`` refuses such a
  station at once, from the file alone (:func:`refuse_edge_stations`): one
  line, exit status 2, before it opens zenoh. So it never races the
  acquisition for the station, in whichever order the two are started;
- ``"line"``: a ``boltwatch serve predictor`` decides, over zenoh.

Every predictor (the line's, and a station's edge predictor) holds the
liveliness token ``boltwatch/<station>/health/predictor``; a predictor about
to start asks the line for those tokens first
(:func:`refuse_stations_served_elsewhere`). With the placement checked first,
that only ever meets a twin of its own kind: a second line predictor for a
line station, a second acquisition for an edge station.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import zenoh

from shared.config import LoadedStation
from shared.contract import keys
from shared.errors import ConfigError


def refuse_edge_stations(stations: Sequence[LoadedStation]) -> None:
    """ConfigError naming the files of ``stations`` whose acquisition decides (placement
    ``"edge"``): a line predictor must not serve them."""
    edge = [station for station in stations if station.config.predictor.placement == "edge"]
    if not edge:
        return
    files = ", ".join(str(station.path) for station in edge)
    ids = ", ".join(station.station_id for station in edge)
    starts = "', '".join(f"boltwatch serve acquisition --config {station.path}" for station in edge)
    raise ConfigError(
        f"{files}: predictor.placement: 'edge' (the default): on an edge station the "
        f"acquisition decides ({ids}, on its CAN thread), there is no predictor to start: "
        f"start '{starts}' instead, or set placement = \"line\" for a predictor over zenoh"
    )


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
