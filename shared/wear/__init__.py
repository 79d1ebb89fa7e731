"""The wear ledger: accumulated vibration intensity per tool (eq. 69).

- :mod:`.wear_ledger` (the SQLite ledger), :mod:`.wear_ledger_file` (made whole; a
  broken one recognised and moved aside), :mod:`.wear_reset` (``boltwatch wear reset``)
- :mod:`.wear_bound` (what a run can have taken: the bound a summary must keep)
- :mod:`.wear_since_service` (a tool's intensity since service, kept from the
  runs added), :mod:`.wear_tool_data` (what controllers said of their tools)
- :mod:`.wear_waiting` (runs still waiting when the recorder stops)
- :mod:`.wear_table` (the ledger as a table: ``boltwatch wear``),
  :mod:`.wear_plant` (every line's ledger merged: ``boltwatch wear --plant``)
- when a tool comes due: :mod:`.wear_calendar` (the plant's production days and shifts,
  learned from the runs), :mod:`.wear_forecast` (a tool's pace and its service forecast),
  :mod:`.wear_change` (when a tool's work last changed), :mod:`.wear_outlook` (its pace
  and what wears it: by station, program and joint; what is unusual),
  :mod:`.wear_grouped_runs` and :mod:`.wear_history` (what they read of the ledger),
  :mod:`.wear_joints` (each station's program's joint, from the station files)

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
from shared.wear.wear_calendar import ProductionCalendar, learn_calendar
from shared.wear.wear_forecast import ForecastSettings, ToolForecast, WearPace, forecast
from shared.wear.wear_joints import joint_names
from shared.wear.wear_ledger import RunWear, ToolWear, WearLedger, ledger_path
from shared.wear.wear_ledger_file import APPLICATION_ID, COLUMNS, LEDGER_VERSION, BrokenLedgerError
from shared.wear.wear_outlook import ToolOutlook, UnusualRun, WearCause
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
    "ForecastSettings",
    "ProductionCalendar",
    "RefusedSummaryError",
    "RunLimits",
    "RunWear",
    "StationLimits",
    "ToolForecast",
    "ToolOutlook",
    "ToolWear",
    "UnusualRun",
    "WearCause",
    "WearLedger",
    "WearPace",
    "WearReply",
    "forecast",
    "format_table",
    "joint_names",
    "learn_calendar",
    "ledger_path",
    "load_waiting",
    "merge",
    "parse_reply",
    "refusal",
    "reset_ledger",
    "save_waiting",
    "waiting_path",
]
