"""Which joint each station's program tightens, by name: what a tool's causes of wear are
named by beside station and program (:class:`~.wear_outlook.WearCause`).

A CAN station's program tightens its own joint (``programs[].joint``) or the station's
(``station.joint``); a controller's station names no joint (its psets are the
controller's), so its programs have none here.
"""

from __future__ import annotations

from collections.abc import Iterable

from shared.config import AnyStation, LoadedStation


def joint_names(stations: Iterable[AnyStation]) -> dict[tuple[str, int], str]:
    """(station, program id) -> the name of the joint that program tightens there."""
    names: dict[tuple[str, int], str] = {}
    for station in stations:
        if isinstance(station, LoadedStation):
            for program in station.config.programs:
                names[(station.station_id, program.id)] = station.joint_of(program.id).name
    return names
