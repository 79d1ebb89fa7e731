"""A tool's line of the wear ledger as the values of an IJT tool asset, pure (no asyncua).

:func:`tool_counters` gives what :mod:`.tool_assets` writes into a tool of
``AssetManagement/Assets/Tools`` (an object with IJT's ``IToolType``
interface, OPC 40450-1, 8.3): where each figure goes is said beside it.
Tightenings are the runs the ledger counted (every station's), not a
controller's own count; the dates are the newest of the ledger's service
(``boltwatch wear service``) and what a controller said (Open Protocol MID 0041).
The intensity since service is a lifetime variable whose LimitValue is the
threshold and whose WarningValues are :data:`WARNING_SHARES` of it; beside it,
the tool's service forecast (:func:`shared.wear.forecast`, from the ledger's
outlook of the tool: the date, its 80 % interval, the tightenings left).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from shared.wear import ToolWear, forecast

#: the shares of the threshold at which the lifetime variable warns (DI's WarningValues),
#: where the line's page's meter turns
WARNING_SHARES = (0.8, 0.95)


@dataclass(frozen=True, slots=True)
class ToolCounters:
    tool_id: int
    #: Identification/SerialNumber ("" when no controller named it), Identification/Model
    serial_number: str
    model: str | None
    #: OperationCounters/OperationCycleCounter
    tightenings: int
    #: Maintenance/Service/ServiceCycleCount
    tightenings_since_service: int
    #: LifetimeCounters/StickSlipIntensitySinceService, its LimitValue the recorder's
    #: wear_service_threshold (None: none set); LifetimeCounters/StickSlipIntensity (eq. 69)
    intensity_since_service: float
    intensity_threshold: float | None
    intensity_total: float
    #: .../StickSlipIntensitySinceService/WarningValues (None: no threshold)
    intensity_warnings: list[float] | None
    #: Maintenance/Service/LastService, Maintenance/Calibration/LastCalibration and
    #: CalibrationValue (N·m); None: not known
    last_service_ns: int | None
    last_calibration_ns: int | None
    calibration_value_nm: float | None
    #: LifetimeCounters/StickSlipServiceDue, ...DueEarly, ...DueLate: the forecast date of the
    #: threshold and its 80 % interval (None: no date: not forecast, or due now);
    #: LifetimeCounters/StickSlipTighteningsToService (0: due; None: not known)
    service_due_ns: int | None = None
    service_due_early_ns: int | None = None
    service_due_late_ns: int | None = None
    tightenings_to_service: int | None = None


def tool_counters(
    wear: ToolWear, threshold: float | None, now_ns: int | None = None
) -> ToolCounters:
    """``wear`` (a line of :meth:`~shared.wear.WearLedger.tools`) with the station's
    ``recorder.wear_service_threshold``, its forecast made at ``now_ns`` (default: now)."""
    outlook = wear.outlook
    told = forecast(
        wear.tool_id,
        outlook.pace if outlook else None,
        outlook.calendar if outlook else None,
        wear.intensity_since_service,
        threshold,
        time.time_ns() if now_ns is None else now_ns,
    )
    controller = wear.controller
    services = [wear.last_service_ns, controller.last_service_ns if controller else None]
    known_services = [when for when in services if when is not None]
    return ToolCounters(
        tool_id=wear.tool_id,
        serial_number=controller.tool_serial if controller else "",
        model=controller.tool_model if controller else None,
        tightenings=wear.runs,
        tightenings_since_service=wear.runs_since_service,
        intensity_since_service=wear.intensity_since_service,
        intensity_threshold=threshold,
        intensity_total=wear.total_intensity,
        last_service_ns=max(known_services) if known_services else None,
        last_calibration_ns=controller.last_calibration_ns if controller else None,
        calibration_value_nm=controller.calibration_value_nm if controller else None,
        intensity_warnings=None
        if threshold is None
        else [share * threshold for share in WARNING_SHARES],
        service_due_ns=told.due_ns,
        service_due_early_ns=told.early_ns,
        service_due_late_ns=told.late_ns,
        tightenings_to_service=told.runs_left,
    )
