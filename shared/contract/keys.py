"""Zenoh key expressions of boltwatch: where a station's keys live.

Every station lives under ``boltwatch/<station>/``: its channels
(``boltwatch/<station>/<topic>``, the table of :mod:`shared.contract.channels`), the
liveliness token of each service (``health/<service>``) and the recorder's
queryable of the wear ledger (``wear``).
"""

from __future__ import annotations

ROOT = "boltwatch"

WEAR = "wear"
HEALTH = "health"

EVERYTHING = f"{ROOT}/**"
#: Every topic below every station: samples, tool, bus, events, ..., wear/alert,
#: quality/alert (liveliness tokens ``health/*`` are not puts: not heard here).
ALL_STATION_TOPICS = f"{ROOT}/*/**"


def station_key(station: str, topic: str) -> str:
    """``boltwatch/<station>/<topic>``."""
    return f"{ROOT}/{station}/{topic}"


def health_key(station: str, service: str) -> str:
    """Liveliness token key of ``service`` at ``station``."""
    return f"{ROOT}/{station}/{HEALTH}/{service}"


def split_key(key: str) -> tuple[str, str]:
    """``boltwatch/st1/samples`` -> ``("st1", "samples")``; ``health/x`` keeps its tail.

    Raises ValueError for keys outside ``boltwatch/<station>/...``.
    """
    parts = key.split("/", 2)
    if len(parts) != 3 or parts[0] != ROOT or not parts[1]:
        raise ValueError(f"not a boltwatch station key: {key!r}")
    return parts[1], parts[2]
