"""The wear ledger: accumulated vibration intensity per tool (eq. 69).

- :mod:`.wear_ledger` (the SQLite ledger), :mod:`.wear_ledger_file` (made whole; a
  broken one recognised and moved aside), :mod:`.wear_reset` (``boltwatch wear reset``)
- :mod:`.wear_bound` (what a run can have taken: the bound a summary must keep)
- :mod:`.wear_since_service` (a tool's intensity since service, kept from the
  runs added), :mod:`.wear_tool_data` (what controllers said of their tools)
- :mod:`.wear_waiting` (runs still waiting when the recorder stops)
- :mod:`.wear_table` (the ledger as a table: ``boltwatch wear``),
  :mod:`.wear_plant` (every line's ledger merged: ``boltwatch wear --plant``)

The recorder keeps it up to date and raises its alerts (``services/recorder/wear_watch.py``).
"""

from shared.wear.wear_bound import (
    CONTRACT_LIMITS,
    F_SS_MAX_HZ,
    RefusedSummaryError,
    RunLimits,
    StationLimits,
    refusal,
)
from shared.wear.wear_ledger import RunWear, ToolWear, WearLedger, ledger_path
from shared.wear.wear_ledger_file import APPLICATION_ID, COLUMNS, LEDGER_VERSION, BrokenLedgerError
from shared.wear.wear_plant import WearReply, merge, parse_reply
from shared.wear.wear_reset import reset_ledger
from shared.wear.wear_since_service import ADDED_SINCE
from shared.wear.wear_table import format_table
from shared.wear.wear_waiting import load_waiting, save_waiting, waiting_path

__all__ = [
    "ADDED_SINCE",
    "APPLICATION_ID",
    "COLUMNS",
    "CONTRACT_LIMITS",
    "F_SS_MAX_HZ",
    "LEDGER_VERSION",
    "BrokenLedgerError",
    "RefusedSummaryError",
    "RunLimits",
    "RunWear",
    "StationLimits",
    "ToolWear",
    "WearLedger",
    "WearReply",
    "format_table",
    "ledger_path",
    "load_waiting",
    "merge",
    "parse_reply",
    "refusal",
    "reset_ledger",
    "save_waiting",
    "waiting_path",
]
