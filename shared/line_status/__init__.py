"""What a line's stations say on zenoh, collected: ``boltwatch status`` and the line's page.

Pure aggregation (no zenoh, no clock: the caller feeds what arrives and the
time): :mod:`.station_status` (per station: services alive, sample rate, last
run, decision, summary and result, recorder and predictor health),
:mod:`.status_bus` (the acquisition's rate and bus faults),
:mod:`.status_last_result` (the last tightening result: OK/NOK and why),
:mod:`.status_bridge` (a controller bridge's link, faults and alarms),
:mod:`.status_quality_alert` (the newest active quality alert),
:mod:`.status_wear_forecast` (the tools forecast due for service soon),
:mod:`.status_spool` (a station's spool: what waits for the recorder, alerts).
``boltwatch status`` prints it (``services.cli.station_status_text``);
``boltwatch serve dashboard`` serves it live (``services.dashboard``).
"""

from shared.line_status.station_status import (
    KNOWN_SERVICES,
    BusHealth,
    LastDecision,
    LastRun,
    LastSummary,
    PredictorHealth,
    RecorderHealth,
    StationStatus,
    StatusCollector,
    StatusReport,
    to_json,
)
from shared.line_status.status_bridge import bridge_lines
from shared.line_status.status_last_result import amount_text, last_result, result_text
from shared.line_status.status_quality_alert import quality_text
from shared.line_status.status_spool import SpoolStatus, spool_text
from shared.line_status.status_wear_forecast import DueSoon, due_soon_text

__all__ = [
    "KNOWN_SERVICES",
    "BusHealth",
    "DueSoon",
    "LastDecision",
    "LastRun",
    "LastSummary",
    "PredictorHealth",
    "RecorderHealth",
    "SpoolStatus",
    "StationStatus",
    "StatusCollector",
    "StatusReport",
    "amount_text",
    "bridge_lines",
    "due_soon_text",
    "last_result",
    "quality_text",
    "result_text",
    "spool_text",
    "to_json",
]
