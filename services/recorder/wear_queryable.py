"""``boltwatch/<station>/wear``: the recorder answers with the wear ledger's lines of the tools
that ran at the station (``boltwatch wear --plant`` asks every line's recorder)."""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from pathlib import Path

import zenoh

from shared.contract import keys
from shared.wear import WearLedger

LOG = logging.getLogger(__name__)


def wear_replier(ledger_file: Path, host: str, station: str) -> Callable[[zenoh.Query], None]:
    """The queryable's callback for ``station``: replies from ``ledger_file`` naming ``host``
    (with the ledger's path, which ledger a reply comes from: a plant has several)."""

    def reply(query: zenoh.Query) -> None:
        # finalized on leaving (the querier's get ends now), not when the Query is freed:
        # an error's traceback, kept by a log record, would keep it until its timeout
        with query:
            _reply(ledger_file, host, station, query)

    return reply


def _reply(ledger_file: Path, host: str, station: str, query: zenoh.Query) -> None:
    try:
        with WearLedger(ledger_file, read_only=True) as ledger:
            tools = [tool.to_dict() for tool in ledger.tools(station=station)]
    except Exception as err:  # a reply, never a dead queryable thread
        LOG.warning("wear query of %s failed: %s", station, err)
        query.reply_err(str(err).encode())
        return
    reply = {"station": station, "ledger": str(ledger_file), "host": host, "tools": tools}
    # on the station's own key, never the query's: a plant-wide get of
    # boltwatch/*/wear would otherwise see every recorder's reply under one key,
    # and zenoh's default consolidation keeps one of them
    query.reply(keys.station_key(station, keys.WEAR), json.dumps(reply).encode())
