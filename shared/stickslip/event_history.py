"""The youngest stick-slip events of a run: what the fits and the next event's figures need.

One object instead of parallel lists trimmed by hand: per event its peak
time t_j, its period Δt_j (none for the first event), its peak torque
T_max,j and its force plateau F_j (none without force), each series kept to
the youngest :data:`HISTORY` values (the fits of :mod:`.regression` use at
most 8). It also keeps what the next event is measured from: the previous
event's trough sample (where the next stick phase's plateau begins) and its
peak angle (the motor speed between two peaks).
"""

from __future__ import annotations

import itertools
import math

HISTORY = 10  # events kept for the fits (the fits use at most 8)


class EventHistory:
    """The youngest events' times, periods, peaks and plateaus, oldest first."""

    __slots__ = ("peak_angle_deg", "peaks_nm", "periods_s", "plateaus_n", "times_s", "trough_index")

    def __init__(self) -> None:
        self.times_s: list[float] = []
        self.periods_s: list[float] = []
        self.peaks_nm: list[float] = []
        self.plateaus_n: list[float] = []
        self.trough_index = -1  # the sample of the newest event's trough; -1 before the first
        self.peak_angle_deg = math.nan  # the newest event's peak angle

    @property
    def newest_time_s(self) -> float | None:
        return self.times_s[-1] if self.times_s else None

    @property
    def newest_peak_nm(self) -> float | None:
        return self.peaks_nm[-1] if self.peaks_nm else None

    @property
    def newest_plateau_n(self) -> float | None:
        return self.plateaus_n[-1] if self.plateaus_n else None

    def add(
        self,
        time_s: float,
        period_s: float | None,
        peak_nm: float,
        plateau_n: float | None,
        trough_index: int,
        peak_angle_deg: float,
    ) -> None:
        """Event j: its peak, period (None for the first), plateau (None without force)."""
        self.times_s.append(time_s)
        if period_s is not None:
            self.periods_s.append(period_s)
        self.peaks_nm.append(peak_nm)
        if plateau_n is not None:
            self.plateaus_n.append(plateau_n)
        for series in (self.times_s, self.periods_s, self.peaks_nm, self.plateaus_n):
            if len(series) > HISTORY:
                del series[0]
        self.trough_index = trough_index
        self.peak_angle_deg = peak_angle_deg

    def peaks_rise(self, count: int) -> bool:
        """The youngest ``count`` peaks rise one after the other (False with fewer events)."""
        peaks = self.peaks_nm[-count:]
        return len(peaks) >= count and all(b > a for a, b in itertools.pairwise(peaks))

    def has(self, count: int) -> bool:
        """At least ``count`` events are kept."""
        return len(self.peaks_nm) >= count
