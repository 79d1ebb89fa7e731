"""Maxima and minima of the inclination window paired into slips, above a noise floor.

A sign flip of the window's inclination (eq. 47) marks a candidate maximum
or minimum. On a slow stick ramp with noise, the short window flips now and
then without any slip; such a wiggle pairs a maximum with a minimum only a
few noise amplitudes below it. A pair counts as a slip only when its drop
T_max - T_min exceeds the noise floor::

    drop > max(NOISE_FACTOR · d2, REL_FLOOR · |T_max|)

where d2 tracks the running median of |T_i - 2 T_(i-1) + T_(i-2)| (for white
noise of σ, about 1.65 σ) by multiplicative steps of ±NOISE_STEP, O(1) per
sample. It starts from the median of the first SEED_SAMPLES values, not
from one: a single |d2| can lie anywhere from 0 to several σ, and at 2 % per
sample a start 25 times too low (seed 1, joint 80 of the accuracy benchmark:
0.013 Nm against 0.33 Nm) took about 400 samples to climb out, while the
wiggles of a slow stick ramp passed as slips. Until SEED_SAMPLES values exist
the estimate is the (upper) median of those seen so far.

A median, not a mean: below about 100 Hz the kinks of the slips are a small
share of the samples and barely lift it, whereas a mean grows with their
rate. Above, they are most samples and the median sees them: with the rig's
0.2 Nm noise the floor is 1.0 Nm below 50 Hz, 1.9 Nm at 150-200 Hz and
2.8 Nm at 200-300 Hz (median at the true slips; see the window docstring in
:mod:`.settings`).
A rejected wiggle forgets its maximum: the ramp goes on to a higher one.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from services.predictor.core.inclination_window import (
    MAX_PASSED,
    MIN_PASSED,
    InclinationWindow,
)

NOISE_FACTOR = 3.0
REL_FLOOR = 0.002
NOISE_STEP = 0.02
SEED_SAMPLES = 32  # |d2| values whose median starts the running estimate


@dataclass(frozen=True, slots=True)
class Extremum:
    """One sample of the window picked as a maximum or minimum."""

    index: int  # sample index within the run
    time_s: float
    torque_nm: float
    force_n: float
    angle_deg: float


@dataclass(frozen=True, slots=True)
class Slip:
    """A confirmed slip: the torque peak before it and the minimum after it."""

    peak: Extremum
    trough: Extremum


class ExtremumTracker:
    """Feed flips of an :class:`InclinationWindow`; get a :class:`Slip` when one is confirmed."""

    def __init__(self) -> None:
        self._pending_max: Extremum | None = None
        self.last_trough: Extremum | None = None
        self.noise_d2_nm = 0.0
        self._t1 = math.nan
        self._t2 = math.nan
        self._seed_d2_nm: list[float] = []  # the first SEED_SAMPLES |d2|, then unused
        self._seeded = False
        self.rejected = 0

    def observe_torque(self, torque_nm: float) -> None:
        """Update the noise estimate with the newest accepted torque sample."""
        t1 = self._t1
        if not (math.isnan(t1) or math.isnan(self._t2)):  # both seen
            d2 = abs(torque_nm - 2.0 * t1 + self._t2)
            est = self.noise_d2_nm
            if not self._seeded:
                self._seed(d2)
            elif d2 > est:
                self.noise_d2_nm = est * (1.0 + NOISE_STEP)
            else:
                self.noise_d2_nm = est * (1.0 - NOISE_STEP)
        self._t2 = t1
        self._t1 = torque_nm

    def _seed(self, d2_nm: float) -> None:
        """Start-up: the estimate is the exact (upper) median of the |d2| seen so far."""
        values = self._seed_d2_nm
        bisect.insort(values, d2_nm)
        self.noise_d2_nm = max(values[len(values) // 2], 1e-12)
        if len(values) >= SEED_SAMPLES:
            self._seeded = True
            values.clear()

    def on_flip(self, flip: int, window: InclinationWindow) -> Slip | None:
        """Handle a MAX_PASSED or MIN_PASSED flip; returns the slip it confirms, if any."""
        if flip == MAX_PASSED:
            after = self.last_trough.index if self.last_trough is not None else -1
            slot = window.argmax(after)
            if slot < 0:
                return None
            candidate = _extremum(window, slot)
            pending = self._pending_max
            if pending is None or candidate.torque_nm >= pending.torque_nm:
                self._pending_max = candidate
            return None
        if flip != MIN_PASSED:
            return None
        pending = self._pending_max
        slot = window.argmin(pending.index if pending is not None else -1)
        if slot < 0:
            return None
        trough = _extremum(window, slot)
        self._pending_max = None
        if pending is None:
            self.last_trough = trough
            return None
        drop = pending.torque_nm - trough.torque_nm
        if drop > self.min_drop_nm(pending.torque_nm):
            self.last_trough = trough
            return Slip(pending, trough)
        self.rejected += 1
        return None

    def min_drop_nm(self, peak_torque_nm: float) -> float:
        """The noise floor a drop must exceed to count as a slip."""
        return max(NOISE_FACTOR * self.noise_d2_nm, REL_FLOOR * abs(peak_torque_nm))


def _extremum(window: InclinationWindow, slot: int) -> Extremum:
    return Extremum(
        window.index[slot],
        window.time_s[slot],
        window.torque_nm[slot],
        window.force_n[slot],
        window.angle_deg[slot],
    )
