"""``boltwatch/<station>/wear``: the recorder answers with the wear ledger's lines of the tools
that ran at the station (``boltwatch wear --plant`` asks every line's recorder, the line's
page every 2 s), and beside them (``outlooks``, by tool id) each tool's outlook: its pace and
calendar, from which any reader forecasts its service against its threshold, and what wears
it (:mod:`shared.wear.wear_outlook`)."""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Mapping
from pathlib import Path

import zenoh

from shared.contract import keys
from shared.wear import WearLedger

LOG = logging.getLogger(__name__)


def wear_replier(
    ledger_file: Path,
    host: str,
    station: str,
    joints: Mapping[tuple[str, int], str] | None = None,
) -> Callable[[zenoh.Query], None]:
    """The queryable's callback for ``station``: replies from ``ledger_file`` naming ``host``
    (with the ledger's path, which ledger a reply comes from: a plant has several); each
    tool's causes of wear name the joint of each station's program in ``joints``."""

    def reply(query: zenoh.Query) -> None:
        # finalized on leaving (the querier's get ends now), not when the Query is freed:
        # an error's traceback, kept by a log record, would keep it until its timeout
        with query:
            _reply(ledger_file, host, station, joints, query)

    return reply


def _reply(
    ledger_file: Path,
    host: str,
    station: str,
    joints: Mapping[tuple[str, int], str] | None,
    query: zenoh.Query,
) -> None:
    try:
        reply = reply_body(ledger_file, host, station, joints)
    except Exception as err:  # a reply, never a dead queryable thread
        LOG.warning("wear query of %s failed: %s", station, err)
        query.reply_err(str(err).encode())
        return
    # on the station's own key, never the query's: a plant-wide get of
    # boltwatch/*/wear would otherwise see every recorder's reply under one key,
    # and zenoh's default consolidation keeps one of them
    query.reply(keys.station_key(station, keys.WEAR), reply)


def reply_body(
    ledger_file: Path,
    host: str,
    station: str,
    joints: Mapping[tuple[str, int], str] | None = None,
) -> bytes:
    """The reply for ``station``: its tools' lines, and each one's outlook beside them (which
    a plant's older boltwatch reads as it was); the ledger's errors raised."""
    with WearLedger(ledger_file, read_only=True) as ledger:
        tools = [tool.to_dict() for tool in ledger.tools(station=station, joints=joints)]
    outlooks = {str(tool["tool_id"]): tool.pop("outlook") for tool in tools}
    reply = {
        "station": station,
        "ledger": str(ledger_file),
        "host": host,
        "tools": tools,
        "outlooks": outlooks,
    }
    return json.dumps(reply).encode()
