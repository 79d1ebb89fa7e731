"""Zenoh key expressions of boltwatch: where a station's keys live.

Every station lives under ``boltwatch/<station>/``: its channels
(``boltwatch/<station>/<topic>``, the table of :mod:`shared.contract.channels`), the
liveliness token of each service (``health/<service>``), the recorder's
queryable of the wear ledger (``wear``), and what a station's spool sends
again for the line's recorder (``again/<topic>``: a live subscriber of
``<topic>`` never hears old messages; :mod:`shared.spool`).
"""

from __future__ import annotations

ROOT = "boltwatch"

WEAR = "wear"
HEALTH = "health"
AGAIN = "again"

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


def again_key(station: str, topic: str) -> str:
    """``boltwatch/<station>/again/<topic>``: a spooled message of ``topic`` sent again."""
    return f"{ROOT}/{station}/{AGAIN}/{topic}"


def live_key_of(key: str) -> str | None:
    """The channel key an ``again/<topic>`` key stands for (None: not one)."""
    parts = key.split("/", 3)
    if len(parts) != 4 or parts[0] != ROOT or parts[2] != AGAIN or not parts[3]:
        return None
    return f"{ROOT}/{parts[1]}/{parts[3]}"
