"""Bad input made safe, once, at the core's boundary: nothing non-finite or absurd gets past.

Every sample is checked here and what was done is counted in
:class:`InputReport`; the rest of the core sees finite values only.

- time not finite, torque not finite, or torque outside the sensor's range
  (:class:`~shared.contract.sensor_range.SensorRange`: what it can measure): the
  sample is dropped (``bad_time``, ``bad_torque``, ``implausible``);
- time earlier than the last accepted sample (out of order): dropped;
- time equal to the last one (repeated timestamp): kept; the inclination
  window clamps its Δt (see :mod:`.inclination_window`);
- a jump: the first sample of a run, and any sample more than
  :data:`GAP_PERIODS` nominal periods after the last accepted one, is held
  until the next sample says which it was. A next sample close after it
  confirms it (a real gap, counted in ``gaps``; or the run's start) and both
  are used; a next sample that goes on from the old time shows it was one
  bad timestamp (``bad_time``: one sample stamped an hour ahead is one bad
  sample, not the end of the run) and it is dropped. A jump of more than
  :data:`MAX_JUMP_S` is a bad timestamp whatever follows (two absurd stamps
  in a row would otherwise confirm each other). When the run's first two
  samples disagree (one of them absurd), the third decides between them;
  two absurd stamps among a run's first three samples cannot be told from
  its start;
- force missing, not finite or outside the range, on a station with a force
  sensor: the last good force is held (``held_force``; the plateau does not
  move during a stick phase anyway) for the stop rules, and marked as not
  measured: a plateau's mean leaves it out (held across a slip, it would
  pull the new plateau toward the old one). Before the first good force of the run
  there is none to hold: the sample has no force (``no_force``), which the
  plateau means and the force rules skip, so a lost first frame costs one
  sample, not the run;
- angle not finite or outside the range: the last good angle is held
  (``held_angle``; 0 before the first, the angle counts from the run's start)
  and marked as not measured: a held angle looks like a motor standing
  still, so the slip rule of :mod:`.motor_motion` does not judge with it;
- torque at the end of the sensor's range (a clipped sensor): kept, counted
  as ``saturated``.

Only a long stretch of unusable samples (``fault_samples`` in a row) turns
into a stop (input_fault): going on would be blind.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from shared.contract import SensorRange

GAP_PERIODS = 5.0  # a Δt above this many nominal periods is a jump: held for the next sample
MAX_JUMP_S = 10.0  # a jump longer than this within a run is a bad timestamp, whatever follows
FIRST_DT_MAX_S = 1.0  # the second sample confirms the run's first when at most this later

DROP = 0  # nothing to use
USE = 1  # use this sample (:attr:`InputGuard.sample`)
HOLD = 2  # this sample is held until the next one says what it was: nothing to use now
USE_HELD = 3  # use the held sample (:attr:`InputGuard.confirmed`), then this one
USE_HELD_HOLD = 4  # use the held sample (:attr:`InputGuard.confirmed`); this one is held


@dataclass(slots=True)
class InputReport:
    """Counts of what the guard did with the input of one run."""

    samples: int = 0
    accepted: int = 0
    bad_time: int = 0
    bad_torque: int = 0
    implausible: int = 0  # a finite value outside what the sensor can measure
    out_of_order: int = 0
    repeated_time: int = 0
    gaps: int = 0
    held_force: int = 0
    no_force: int = 0
    held_angle: int = 0
    saturated: int = 0
    longest_bad_run: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


#: One accepted sample, finite throughout: (time_s, torque_nm, force_n, angle_deg,
#: angle_measured, force_measured); force_n is None when the sample has no force (no sensor,
#: or none yet in this run); angle_measured / force_measured are False when that value is
#: held (the last good one, not measured: a plateau's mean leaves a held force out).
GuardedSample = tuple[float, float, float | None, float, bool, bool]
RawSample = tuple[float, float, float, float]  # as given: (time_s, torque_nm, force_n, angle_deg)


class InputGuard:
    """Decide per sample: use it, hold it for the next one, or drop it."""

    def __init__(self, has_force: bool, sensor_range: SensorRange) -> None:
        self._has_force = has_force
        self._torque_low, self._torque_high = sensor_range.torque_nm
        self._force_low, self._force_high = sensor_range.force_n
        self._angle_low, self._angle_high = sensor_range.angle_deg
        self.report = InputReport()
        self.last_time_s = -math.inf
        self.nominal_dt_s = 0.0  # running mean of positive Δt, 0 until known
        self.bad_run = 0  # consecutive unusable samples
        self._last_force_n: float | None = None
        self._last_angle_deg = 0.0
        self._held: RawSample | None = None  # a jump (or the run's first sample), undecided
        self._rival: RawSample | None = None  # a second sample that disagreed with the first
        # the largest Δt that is not a jump: before the run's first sample everything is one
        # (-1), then the first step (FIRST_DT_MAX_S) until Δt is known
        self._max_dt_s = -1.0
        #: the sample to use on USE and USE_HELD
        self.sample: GuardedSample = (0.0, 0.0, None, 0.0, True, True)
        #: the held sample, confirmed, to use first on USE_HELD and USE_HELD_HOLD
        self.confirmed: GuardedSample = (0.0, 0.0, None, 0.0, True, True)

    def check(self, time_s: float, torque_nm: float, force_n: float, angle_deg: float) -> int:
        """DROP, USE, HOLD, USE_HELD or USE_HELD_HOLD (see the module's constants)."""
        report = self.report
        report.samples += 1
        if not math.isfinite(time_s):
            report.bad_time += 1
            return self._bad()
        if not self._torque_low <= torque_nm <= self._torque_high:
            if math.isfinite(torque_nm):
                report.implausible += 1
            else:
                report.bad_torque += 1
            return self._bad()
        held = self._held
        if held is None:
            dt_s = time_s - self.last_time_s
            if (
                0.0 < dt_s <= self._max_dt_s
                and (not self._has_force or self._force_low <= force_n <= self._force_high)
                and self._angle_low <= angle_deg <= self._angle_high
            ):
                # the usual sample, inline (a thousand a second per station): what _use does
                nominal = self.nominal_dt_s
                nominal += 0.05 * (dt_s - nominal)
                self.nominal_dt_s = nominal
                self._max_dt_s = GAP_PERIODS * nominal
                self.bad_run = 0
                report.accepted += 1
                self.last_time_s = time_s
                self._last_angle_deg = angle_deg
                if torque_nm == self._torque_high or torque_nm == self._torque_low:  # noqa: PLR1714
                    report.saturated += 1
                if self._has_force:
                    self._last_force_n = force_n
                    self.sample = (time_s, torque_nm, force_n, angle_deg, True, True)
                else:
                    self.sample = (time_s, torque_nm, None, angle_deg, True, True)
                return USE
            return self._unusual(dt_s, (time_s, torque_nm, force_n, angle_deg))
        return self._after_jump(held, (time_s, torque_nm, force_n, angle_deg))

    def _unusual(self, dt_s: float, raw: RawSample) -> int:
        """Nothing held, but not the usual sample: out of order, repeated, a bad value, a jump."""
        if dt_s < 0.0:
            self.report.out_of_order += 1
            return self._bad()
        if dt_s <= self._max_dt_s:
            self.sample = self._use(*raw)
            return USE
        if dt_s > MAX_JUMP_S and self.last_time_s > -math.inf:
            self.report.bad_time += 1
            return self._bad()
        return self._hold(raw)

    def _after_jump(self, held: RawSample, raw: RawSample) -> int:
        """A sample held (a jump, or the run's first): this one says which it was."""
        report = self.report
        time_s = raw[0]
        if time_s - self.last_time_s > MAX_JUMP_S and self.last_time_s > -math.inf:
            report.bad_time += 1
            return self._bad()
        after_held_s = time_s - held[0]
        rival, self._rival = self._rival, None
        if 0.0 <= after_held_s <= self._max_dt_s:
            if rival is not None:
                report.bad_time += 1  # the run's second sample was the bad one
            self.confirmed = self._use(*held, jump=True)
            self.sample = self._use(*raw)
            return USE_HELD
        if rival is not None:
            # the run's first two samples disagreed and this one goes with the second
            report.bad_time += 1
            if 0.0 <= time_s - rival[0] <= self._max_dt_s:
                self.confirmed = self._use(*rival, jump=True)
                self.sample = self._use(*raw)
                return USE_HELD
            report.bad_time += 1  # with neither: both go, this one is the first now
            self._held = None
            return self._hold(raw)
        after_last_s = time_s - self.last_time_s
        if 0.0 <= after_last_s <= self._max_dt_s:
            self._held = None  # it was one bad timestamp; this one goes on from the last
            report.bad_time += 1
            self.sample = self._use(*raw)
            return USE
        if after_held_s > 0.0 and self.last_time_s > -math.inf:
            # a jump after a jump: time moved on (a real gap), and this one is a jump again
            self.confirmed = self._use(*held, jump=True)
            self._hold(raw)
            return USE_HELD_HOLD
        if after_last_s < 0.0:
            report.out_of_order += 1
            return self._bad()
        # the run's first sample and this one disagree: the next one tells which is wrong
        self._rival = raw
        return HOLD

    def _hold(self, raw: RawSample) -> int:
        if self.last_time_s == -math.inf:
            self._max_dt_s = FIRST_DT_MAX_S  # the next sample confirms the first this close
        self._held = raw
        self.bad_run = 0
        return HOLD

    def _use(
        self, time_s: float, torque_nm: float, force_n: float, angle_deg: float, jump: bool = False
    ) -> GuardedSample:
        """Accept a sample: count it, move the clock on; its usable values."""
        report = self.report
        dt_s = time_s - self.last_time_s
        if jump:
            self._held = None
            if self.last_time_s > -math.inf:
                report.gaps += 1
        elif dt_s == 0.0:
            report.repeated_time += 1
        else:
            nominal = self.nominal_dt_s
            nominal = dt_s if nominal == 0.0 else nominal + 0.05 * (dt_s - nominal)
            self.nominal_dt_s = nominal
            self._max_dt_s = GAP_PERIODS * nominal
        self.bad_run = 0
        report.accepted += 1
        self.last_time_s = time_s
        if torque_nm == self._torque_high or torque_nm == self._torque_low:  # noqa: PLR1714
            report.saturated += 1
        force: float | None = None
        force_measured = True
        if self._has_force:
            if self._force_low <= force_n <= self._force_high:
                force = self._last_force_n = force_n
            elif self._last_force_n is None:
                report.no_force += 1
            else:
                force = self._last_force_n
                force_measured = False
                report.held_force += 1
        measured = self._angle_low <= angle_deg <= self._angle_high
        if measured:
            self._last_angle_deg = angle_deg
        else:
            report.held_angle += 1
        return (time_s, torque_nm, force, self._last_angle_deg, measured, force_measured)

    def _bad(self) -> int:
        self.bad_run += 1
        self.report.longest_bad_run = max(self.report.longest_bad_run, self.bad_run)
        return DROP
