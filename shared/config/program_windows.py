"""The windows of a program: where a run's final torque, angle and preload must end to be OK.

A plant judges every tightening against windows: the final torque between
``torque_min_nm`` and ``torque_max_nm``, the final angle between
``angle_min_deg`` and ``angle_max_deg``, the final preload between
``force_min_n`` and ``force_max_n``. Each bound is optional: a figure with
no bound is not judged, a figure with one bound is judged against that one.
The run's ``TighteningResult`` says each figure's status (low / ok / high,
or not judged) and the run's OK/NOK (:mod:`shared.quality.verdict`).

Refused at start, naming the file and the key (the validators below and
:func:`shared.config.station.load_station`): a minimum not below its maximum, a minimum the
tool can never reach before its own hard limit (``max_torque_nm``,
``max_force_n``, ``max_angle_deg``: every run would be NOK), a bound outside
what the station's sensor can report (the DBC's range: a value the run could
never be judged against), a preload window on a station without a force
sensor.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from shared.config.loading import StrictModel
from shared.contract import SensorRange

#: (figure, its minimum's key, its maximum's key, the hard limit's key, unit)
WINDOWS = (
    ("torque", "torque_min_nm", "torque_max_nm", "max_torque_nm", "Nm"),
    ("angle", "angle_min_deg", "angle_max_deg", "max_angle_deg", "deg"),
    ("force", "force_min_n", "force_max_n", "max_force_n", "N"),
)


class ProgramWindows(StrictModel):
    """The window keys of a ``[[programs]]`` entry (each optional)."""

    torque_min_nm: float | None = Field(
        default=None, description="final torque below it: low (NOK); none: no lower bound"
    )
    torque_max_nm: float | None = Field(default=None, description="final torque above it: high")
    angle_min_deg: float | None = Field(
        default=None, description="final angle (since the run started) below it: low"
    )
    angle_max_deg: float | None = Field(default=None, description="final angle above it: high")
    force_min_n: float | None = Field(default=None, description="final preload below it: low")
    force_max_n: float | None = Field(default=None, description="final preload above it: high")

    @model_validator(mode="after")
    def _windows_are_open(self) -> ProgramWindows:
        for _, low_key, high_key, _, unit in WINDOWS:
            low, high = getattr(self, low_key), getattr(self, high_key)
            if low is not None and high is not None and low >= high:
                raise ValueError(
                    f"{low_key} {low:g} {unit} is not below {high_key} {high:g} {unit}: "
                    "no run could be OK"
                )
        return self

    def windows_past_limits(self) -> str | None:
        """A minimum at or above its hard limit (``max_torque_nm``, ...), or None; the
        program's validator asks, after its own limits are checked."""
        for _, low_key, _, limit_key, unit in WINDOWS:
            low, limit = getattr(self, low_key), getattr(self, limit_key, None)
            if low is not None and limit is not None and low >= limit:
                return (
                    f"{low_key} {low:g} {unit} is not below the hard limit {limit_key} "
                    f"{limit:g} {unit}: the tool stops before it, every run would be NOK"
                )
        return None

    def window(self, figure: str) -> tuple[float | None, float | None]:
        """(minimum, maximum) of ``figure`` ("torque", "angle", "force"); None: no bound."""
        for name, low_key, high_key, _, _ in WINDOWS:
            if name == figure:
                return getattr(self, low_key), getattr(self, high_key)
        raise KeyError(figure)

    @property
    def has_force_window(self) -> bool:
        return self.force_min_n is not None or self.force_max_n is not None

    def windows_beyond(self, sensor_range: SensorRange) -> str | None:
        """What bound of this program's windows its sensors cannot report, or None."""
        ranges = {
            "torque": sensor_range.torque_nm,
            "angle": sensor_range.angle_deg,
            "force": sensor_range.force_n,
        }
        for figure, low_key, high_key, _, unit in WINDOWS:
            low, high = ranges[figure]
            for key in (low_key, high_key):
                value = getattr(self, key)
                if value is not None and not low <= value <= high:
                    return (
                        f"{key}: {value:g} {unit} is beyond what the sensor can report "
                        f"({low:g} to {high:g} {unit})"
                    )
        return None
