"""Maxima and minima of the inclination window paired into slips, above a noise floor.

A sign flip of the window's inclination (eq. 47) marks a candidate maximum
or minimum. On a slow stick ramp with noise, the short window flips now and
then without any slip; such a wiggle pairs a maximum with a minimum only a
few noise amplitudes below it. A pair counts as a slip only when its drop
T_max - T_min exceeds the noise floor::

    drop > max(NOISE_FACTOR · d2, REL_FLOOR · |T_max|, RESOLUTION_STEPS · q)

where d2 is the running median of |T_i - 2 T_(i-1) + T_(i-2)| (for white
noise of σ, about 1.65 σ; :mod:`.second_difference`) and q the resolution of
the recorded torque, when known (:mod:`.signal_resolution`: a signal flat at
its resolution has a median |d2| of 0).

Below about 100 Hz the kinks of the slips are a small share of the samples
and barely lift that median; above, they are most samples and it sees them:
with the rig's 0.2 Nm noise the floor is 1.0 Nm below 50 Hz, 1.9 Nm at
150-200 Hz and 2.8 Nm at 200-300 Hz (median at the true slips; see the window
docstring in :mod:`.settings`).

A drop above the floor is a slip only if the motor drove through it
(:mod:`.motor_motion`): the tool letting go after its last step, a pause
between steps and a step to a slower speed drop the torque too, but with the
motor standing or slowed down, and no renewed rise of a stick phase follows.
A rejected drop forgets its maximum: the ramp goes on to a higher one.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.stickslip.inclination_window import MAX_PASSED, MIN_PASSED, InclinationWindow
from shared.stickslip.motor_motion import MotorMotion
from shared.stickslip.second_difference import SecondDifferenceNoise

NOISE_FACTOR = 3.0
REL_FLOOR = 0.002
#: a drop must span more than this many steps of the torque's resolution (three, as three
#: median |d2|, and half a step so that three steps read in floating point stay under it)
RESOLUTION_STEPS = NOISE_FACTOR + 0.5


@dataclass(frozen=True, slots=True)
class Extremum:
    """One sample of the window picked as a maximum or minimum."""

    index: int  # sample index within the run
    time_s: float
    torque_nm: float
    angle_deg: float


@dataclass(frozen=True, slots=True)
class Slip:
    """A confirmed slip: the torque peak before it and the minimum after it."""

    peak: Extremum
    trough: Extremum


class ExtremumTracker:
    """Feed flips of an :class:`InclinationWindow`; get a :class:`Slip` when one is confirmed."""

    def __init__(self, motion: MotorMotion, torque_resolution_nm: float = 0.0) -> None:
        self._motion = motion
        self.torque_resolution_nm = torque_resolution_nm  # q, 0: not known
        self._pending_max: Extremum | None = None
        self.last_trough: Extremum | None = None
        #: the torque's noise: feed it every accepted torque sample (``torque_noise.add``)
        self.torque_noise = SecondDifferenceNoise()
        self.rejected = 0  # drops within the noise floor
        self.not_driven = 0  # drops above it with the motor standing or slowed down

    @property
    def noise_d2_nm(self) -> float:
        """The running median |d2| of the torque."""
        return self.torque_noise.median

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
        if drop <= self.min_drop_nm(pending.torque_nm):
            self.rejected += 1
            return None
        if not self._motion.drove_through(pending.index, window.index[window.head]):
            self.not_driven += 1
            return None
        self.last_trough = trough
        return Slip(pending, trough)

    def min_drop_nm(self, peak_torque_nm: float) -> float:
        """The noise floor a drop must exceed to count as a slip."""
        return slip_floor_nm(self.noise_d2_nm, peak_torque_nm, self.torque_resolution_nm)


def slip_floor_nm(
    noise_d2_nm: float, peak_torque_nm: float, torque_resolution_nm: float = 0.0
) -> float:
    """The floor a drop from ``peak_torque_nm`` must exceed to be a slip, with the torque's
    running median |d2| at ``noise_d2_nm`` and its resolution (module docstring)."""
    return max(
        NOISE_FACTOR * noise_d2_nm,
        REL_FLOOR * abs(peak_torque_nm),
        RESOLUTION_STEPS * torque_resolution_nm,
    )


def _extremum(window: InclinationWindow, slot: int) -> Extremum:
    return Extremum(
        window.index[slot],
        window.time_s[slot],
        window.torque_nm[slot],
        window.angle_deg[slot],
    )
