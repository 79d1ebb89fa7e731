"""Bad input made safe: every sample is checked once, and what was done is counted.

The rules (each counted in :class:`InputReport`):

- time not finite, torque not finite, or time earlier than the last accepted
  sample (out of order): the sample is dropped;
- time equal to the last one (repeated timestamp): kept; the inclination
  window clamps its Δt (see :mod:`.inclination_window`);
- a gap longer than five nominal periods: kept and counted;
- force not finite on a station with a force sensor: the last good force is
  held (the plateau does not move during a stick phase anyway);
- torque repeating exactly at the highest value seen (a clipped sensor):
  kept, counted as saturated.

Only a long stretch of unusable samples (``fault_samples`` in a row) turns
into a stop (input_fault): going on would be blind.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

GAP_PERIODS = 5.0  # a Δt above this many nominal periods is a gap


@dataclass(slots=True)
class InputReport:
    """Counts of what the guard did with the input of one run."""

    samples: int = 0
    accepted: int = 0
    bad_time: int = 0
    bad_torque: int = 0
    out_of_order: int = 0
    repeated_time: int = 0
    gaps: int = 0
    held_force: int = 0
    saturated: int = 0
    longest_bad_run: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


class InputGuard:
    """Decide per sample: use it (with a usable force) or drop it."""

    def __init__(self, has_force: bool) -> None:
        self._has_force = has_force
        self.report = InputReport()
        self.last_time_s = -math.inf
        self.last_force_n = math.nan
        self.nominal_dt_s = 0.0  # running mean of positive Δt, 0 until known
        self._max_torque_nm = -math.inf
        self._last_torque_nm = math.nan
        self.bad_run = 0  # consecutive unusable samples

    def check(self, time_s: float, torque_nm: float, force_n: float) -> float | None:
        """The force to use with an accepted sample (NaN when none); None drops the sample."""
        report = self.report
        report.samples += 1
        if not math.isfinite(time_s):
            report.bad_time += 1
            self._bad()
            return None
        if not math.isfinite(torque_nm):
            report.bad_torque += 1
            self._bad()
            return None
        dt_s = time_s - self.last_time_s
        if dt_s < 0.0:
            report.out_of_order += 1
            self._bad()
            return None
        if dt_s == 0.0:
            report.repeated_time += 1
        elif math.isfinite(dt_s):
            nominal = self.nominal_dt_s
            if nominal == 0.0:
                self.nominal_dt_s = dt_s
            elif dt_s > GAP_PERIODS * nominal:
                report.gaps += 1
            else:
                self.nominal_dt_s = nominal + 0.05 * (dt_s - nominal)
        self.bad_run = 0
        report.accepted += 1
        self.last_time_s = time_s
        if torque_nm >= self._max_torque_nm:
            if torque_nm == self._last_torque_nm:
                report.saturated += 1
            self._max_torque_nm = torque_nm
        self._last_torque_nm = torque_nm
        if not self._has_force:
            return math.nan
        if math.isfinite(force_n):
            self.last_force_n = force_n
            return force_n
        report.held_force += 1
        return self.last_force_n

    def _bad(self) -> None:
        self.bad_run += 1
        self.report.longest_bad_run = max(self.report.longest_bad_run, self.bad_run)
