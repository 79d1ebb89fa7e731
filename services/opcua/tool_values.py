"""A tool's line of the wear ledger as the values of an IJT tool asset, pure (no asyncua).

:func:`tool_counters` gives what :mod:`.tool_assets` writes into a tool of
``AssetManagement/Assets/Tools`` (an object with IJT's ``IToolType``
interface, OPC 40450-1, 8.3): where each figure goes is said beside it.
Tightenings are the runs the ledger counted (every station's), not a
controller's own count; the dates are the newest of the ledger's service
(``boltwatch wear service``) and what a controller said (Open Protocol MID 0041).
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.wear import ToolWear


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
    #: Maintenance/Service/LastService, Maintenance/Calibration/LastCalibration and
    #: CalibrationValue (N·m); None: not known
    last_service_ns: int | None
    last_calibration_ns: int | None
    calibration_value_nm: float | None


def tool_counters(wear: ToolWear, threshold: float | None) -> ToolCounters:
    """``wear`` (a line of :meth:`~shared.wear.WearLedger.tools`) with the station's
    ``recorder.wear_service_threshold``."""
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
    )
