"""What a station's sensors can measure: the plausible range of torque, angle and force.

A value outside the range is not a measurement (a corrupt frame, a bad
export, a unit mix-up): the predictor counts it and never lets it move a
decision, and the decoders refuse it. On a live station the range is the
DBC's (each signal's minimum and maximum: what its bits can carry, or the
narrower range the DBC states); offline (``boltwatch predict``, controller
imports) it is :data:`CONTRACT_RANGE`, the range of the DBC this project
ships (``config/can/station.dbc``), unless one is given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from shared.contract.can_database import StationDatabase

Bounds = tuple[float, float]


@dataclass(frozen=True, slots=True)
class SensorRange:
    """Inclusive (low, high) of each measured quantity."""

    torque_nm: Bounds
    angle_deg: Bounds
    force_n: Bounds

    def __post_init__(self) -> None:
        for name in ("torque_nm", "angle_deg", "force_n"):
            low, high = getattr(self, name)
            if not (math.isfinite(low) and math.isfinite(high) and low < high):
                raise ValueError(f"{name}: expected finite low < high, got ({low}, {high})")

    @classmethod
    def of_database(cls, database: StationDatabase) -> SensorRange:
        """The range each contract signal of ``database`` can carry."""
        return cls(
            torque_nm=database.signal_bounds("ToolSensors", "Torque"),
            angle_deg=database.signal_bounds("ToolSensors", "Angle"),
            force_n=database.signal_bounds("JointSensors", "Force"),
        )


#: The range of the contract DBC shipped in config/can/station.dbc (24-bit torque at
#: 1 mNm, 24-bit angle at 0.01°, 32-bit force at 0.1 N); a test keeps them equal.
CONTRACT_RANGE = SensorRange(
    torque_nm=(-8388.608, 8388.607),
    angle_deg=(-83886.08, 83886.07),
    force_n=(-214748364.8, 214748364.7),
)
