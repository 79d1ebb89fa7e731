"""Eq. 71 against the analytical model: K1-K3 of the configured joint (paper Sec. 3.3, 6.6).

When the station names its joint, the model (:mod:`shared.model`) says before
the first event where K1-K3 must lie (eqs. 34-39); a run whose constants sit
outside those bands is not the joint the program was written for:
``constant_out_of_band``. Each event is taken at its own model time
(:meth:`ModelBandCheck.model_time_s`), every band is widened for what the
model cannot see at 1 kHz (:data:`PERIOD_SLACK_SAMPLES`, :data:`MODEL_SLACK`),
the median of the last n_K events is judged, and only events that are
evidence of a slip count (the noise floor settled, a period of one stick
phase: :data:`MIN_STICK_SHARE` of the stick ramp, a rise the noise alone does
not make). Why each rule, and what it prevented:
``docs/explanation/algorithm.md``, "Eq. 71 against the joint model".
"""

from __future__ import annotations

import math
import statistics
from collections import deque
from dataclasses import dataclass

from shared.model import JointConstants, angle_ratio, expected_constant_bands
from shared.stickslip.extremum_tracker import slip_floor_nm

PERIOD_SLACK_SAMPLES = 2.0  # each of the two peaks of a period is read to ±1 sample
MODEL_SLACK = 2.5  # bounds widened ×/÷ this: μ scatter, nominal μ, a missed event
#: a period counts when the torque rose by at least this share of the stick ramp k_e φ̇_m Δt,
#: and that share is above the slip floor (:func:`~.extremum_tracker.slip_floor_nm`)
MIN_STICK_SHARE = 0.5


@dataclass(frozen=True, slots=True)
class BandVerdict:
    """A constant whose median left its widened band."""

    number: int  # 1, 2 or 3
    median: float
    low: float
    high: float

    def detail(self) -> str:
        return (
            f"K{self.number} median {self.median:.4g} outside the model band "
            f"{self.low:.4g} .. {self.high:.4g} (widened, eqs. 34-39, 71)"
        )


class ModelBandCheck:
    """Judges each event's K1-K3 against the configured joint's widened bands."""

    def __init__(
        self, constants: JointConstants, window_events: int, sample_period_s: float = 1e-3
    ) -> None:
        self.constants = constants
        self.window_events = max(1, window_events)
        self.sample_period_s = sample_period_s
        self.gamma_stick = angle_ratio(
            constants.k_e_nm_per_rad, constants.k_s_n_per_rad, constants.r_m, constants.mu_stick
        )
        n = self.window_events
        # (value at the longest, value at the shortest plausible period) per event
        self._k1: deque[tuple[float, float]] = deque(maxlen=n)
        self._k2: deque[tuple[float, float]] = deque(maxlen=n)
        self._k3: deque[float] = deque(maxlen=n)
        self.judged = 0  # events whose constants were compared with the bands
        self.unsettled = 0  # events before the noise floor settled: not judged
        self.not_stick_periods = 0  # periods that were not one stick phase: no K1, K2
        self._noise_settled = False
        self._previous_noise_nm = math.nan
        self._previous_trough_nm = math.nan
        # the largest share of its widened bound a median reached (> 1: out of band)
        self.nearest_edge = {1: 0.0, 2: 0.0, 3: 0.0}

    def model_time_s(self, peak_torque_nm: float, motor_speed_rad_s: float) -> float:
        """t_j, the model time of a peak on the stick line (from the untwisted joint).

        A peak sits on the stick line, T_max = φ_m (1 - γ_stick) k_e (eqs. 16, 19), so
        t_j = T_max,j / (φ̇_m · k_e · (1 - γ_stick)), force sensor or not.
        """
        return peak_torque_nm / (
            motor_speed_rad_s * self.constants.k_e_nm_per_rad * (1.0 - self.gamma_stick)
        )

    def on_event(
        self,
        peak_torque_nm: float,
        torque_drop_nm: float,
        period_s: float | None,
        force_step_n: float | None,
        motor_speed_rad_s: float | None,
        noise_nm: float = 0.0,
        floor_nm: float | None = None,
    ) -> BandVerdict | None:
        """Add event j's figures; a verdict when a median has left its widened band.

        ``noise_nm``: the torque's median |d2|; ``floor_nm``: the drop a slip had to
        exceed (None: :func:`slip_floor_nm` of the noise).
        """
        previous_trough_nm = self._previous_trough_nm
        self._previous_trough_nm = peak_torque_nm - torque_drop_nm
        if not self._noise_settled:
            previous_noise_nm, self._previous_noise_nm = self._previous_noise_nm, noise_nm
            if not noise_nm <= previous_noise_nm:  # still climbing (or the first event)
                self.unsettled += 1
                return None
            self._noise_settled = True
        speed = motor_speed_rad_s
        if speed is None or not math.isfinite(speed) or speed <= 0.0 or peak_torque_nm <= 0.0:
            return None
        t_model = self.model_time_s(peak_torque_nm, speed)
        slack_s = PERIOD_SLACK_SAMPLES * self.sample_period_s
        if period_s is not None and period_s > 0.0:
            # a stick phase rises by at least MIN_STICK_SHARE of the stick ramp; noise alone
            # rises by about a slip floor (a noise "slip" is a peak and a trough of the noise),
            # so a rise asked for that is not above the floor says nothing (a slow ramp, noise
            # events a few ms apart)
            stick_rise_nm = MIN_STICK_SHARE * self.constants.k_e_nm_per_rad * speed * period_s
            rise_nm = peak_torque_nm - previous_trough_nm
            if floor_nm is None:
                floor_nm = slip_floor_nm(noise_nm, peak_torque_nm)
            if not (rise_nm >= stick_rise_nm > floor_nm):
                self.not_stick_periods += 1
                period_s = None  # smooth sliding or noise in between (or no trough): no K1, K2
        if period_s is not None and period_s > 0.0:
            longest, shortest = period_s + slack_s, max(period_s - slack_s, 0.5 * period_s)
            self._k1.append((t_model / longest, t_model / shortest))
            if force_step_n is not None:
                self._k2.append((force_step_n / longest * speed, force_step_n / shortest * speed))
        drop = max(0.0, torque_drop_nm - 2.0 * noise_nm)
        self._k3.append(drop / t_model * speed)
        bands = expected_constant_bands(self.constants, speed)
        verdict = self._judge_pairs(1, self._k1, bands.k1_min, bands.k1_max)
        if verdict is None:
            verdict = self._judge_pairs(2, self._k2, bands.k2_min, bands.k2_max)
        if verdict is None and len(self._k3) == self.window_events:
            median = statistics.median(self._k3)
            high = bands.k3_max * MODEL_SLACK
            self.nearest_edge[3] = max(self.nearest_edge[3], median / high)
            if median > high:
                verdict = BandVerdict(3, median, 0.0, high)
        if len(self._k1) == self.window_events or len(self._k3) == self.window_events:
            self.judged += 1
        return verdict

    def _judge_pairs(
        self, number: int, values: deque[tuple[float, float]], low: float, high: float
    ) -> BandVerdict | None:
        if len(values) < self.window_events:
            return None
        low_w, high_w = low / MODEL_SLACK, high * MODEL_SLACK
        at_longest = statistics.median(v[0] for v in values)
        at_shortest = statistics.median(v[1] for v in values)
        edge = max(at_longest / high_w, low_w / at_shortest if at_shortest > 0.0 else math.inf)
        self.nearest_edge[number] = max(self.nearest_edge[number], edge)
        if at_longest > high_w:
            return BandVerdict(number, at_longest, low_w, high_w)
        if at_shortest < low_w:
            return BandVerdict(number, at_shortest, low_w, high_w)
        return None
