"""What a run's wear can be: the bound every RunSummary must keep to enter the wear ledger.

The ledger adds up process intensities (eq. 69); one false figure falsifies
a tool's total for ever. A summary is refused (and counted) when it is
inconsistent in itself (ended before started, negative counts, more events
than samples/2, more samples than its duration or the program's
``max_time_s`` allows) or its intensity is beyond what the joint's physics
allows: ``I_process <= (n_ss - 1) * T_lim**2 * f_max``, with ``T_lim`` the
program's torque limit (else the top of the sensor's range) and ``f_max`` =
:data:`F_SS_MAX_HZ`. The derivation from eqs. 66-68 and how loose it is:
``docs/explanation/algorithm.md``, "What a run can add to the wear ledger".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from shared.config import AnyStation, LoadedStation
from shared.contract import CONTRACT_RANGE, RunClock, RunSummary, SensorRange
from shared.errors import InputError

#: The contract's sample rate (docs/design.md, "CAN"): ToolSensors at 1 kHz while running.
SAMPLE_RATE_HZ = 1000.0
#: The highest stick-slip frequency a run sampled at SAMPLE_RATE_HZ can show (a peak
#: and a trough sample per period).
F_SS_MAX_HZ = SAMPLE_RATE_HZ / 2
#: A tool's sample clock running fast, relative to the station's.
CLOCK_TOLERANCE = 0.02
#: Samples stamped on receipt at the run's two ends (frames arriving bunched).
EDGE_SAMPLES = 20
#: Time a tool may go on after its time limit before it reports done (stop, settle).
END_GRACE_S = 1.0


class RefusedSummaryError(InputError):
    """A RunSummary the ledger does not count: inconsistent, or beyond its run's bound."""

    def __init__(self, summary: RunSummary, reason: str) -> None:
        self.summary = summary
        self.reason = reason
        super().__init__(
            f"run summary {summary.station}/run{summary.run_id} (tool {summary.tool_id}) "
            f"not counted in the wear ledger: {reason}"
        )


@dataclass(frozen=True, slots=True)
class RunLimits:
    """What bounds one run: its tool's torque limit and its program's time limit."""

    torque_limit_nm: float  # T_lim
    max_time_s: float | None  # the program's max_time_s; None: the run's duration alone
    source: str  # where T_lim comes from, said in a refusal

    def event_bound(self) -> float:
        """The most one event may add: T_lim² · f_max (Nm²/s)."""
        return self.torque_limit_nm**2 * F_SS_MAX_HZ

    def intensity_bound(self, events: int) -> float:
        """The most a run of ``events`` events may have taken: (n_ss − 1) · T_lim² · f_max."""
        return max(events - 1, 0) * self.event_bound()


def torque_top_nm(sensor_range: SensorRange) -> float:
    """The largest torque magnitude a sensor range can carry."""
    low, high = sensor_range.torque_nm
    return max(abs(low), abs(high))


#: The limits of a run no station file describes: the contract DBC's torque range.
CONTRACT_LIMITS = RunLimits(
    torque_top_nm(CONTRACT_RANGE), None, "the contract DBC's torque range (no program known)"
)


def samples_in(duration_s: float) -> float:
    """The most samples a run of ``duration_s`` can carry at the contract's rate."""
    return 1 + EDGE_SAMPLES + max(duration_s, 0.0) * SAMPLE_RATE_HZ * (1 + CLOCK_TOLERANCE)


def refusal(summary: RunSummary, limits: RunLimits) -> str | None:
    """Why ``summary`` may not enter the ledger, or None when it may."""
    intensity = summary.process_intensity
    if not isinstance(intensity, int | float) or not math.isfinite(intensity):
        return f"process intensity {intensity} is not a finite number"
    if intensity < 0:
        return f"process intensity {intensity:.3g} is negative (eq. 67 never is)"
    if summary.ended_ns < summary.started_ns:
        return f"it ended (ended_ns {summary.ended_ns}) before it started ({summary.started_ns})"
    if summary.samples < 0 or summary.events < 0:
        return f"negative counts: {summary.samples} samples, {summary.events} events"
    if 2 * summary.events > summary.samples:
        return (
            f"{summary.events} events in {summary.samples} samples: an event needs a peak "
            "and a trough sample"
        )
    duration_s = RunClock(summary.started_ns).seconds(summary.ended_ns)
    if summary.samples > samples_in(duration_s):
        return (
            f"{summary.samples} samples in {duration_s:.6g} s: more than "
            f"{SAMPLE_RATE_HZ:.0f} Hz can carry ({samples_in(duration_s):.0f})"
        )
    if limits.max_time_s is not None:
        allowed = samples_in(limits.max_time_s + END_GRACE_S)
        if summary.samples > allowed:
            return (
                f"{summary.samples} samples: more than the program's max_time_s "
                f"{limits.max_time_s:g} s allows ({allowed:.0f})"
            )
    bound = limits.intensity_bound(summary.events)
    if intensity > bound:
        return (
            f"process intensity {intensity:.3g} is beyond what {summary.events} events can "
            f"carry: (n_ss − 1) × T_lim² × f_max = {max(summary.events - 1, 0)} × "
            f"({limits.torque_limit_nm:g} Nm)² × {F_SS_MAX_HZ:g} Hz = {bound:.3g} "
            f"(T_lim: {limits.source})"
        )
    return None


class StationLimits:
    """The limits of each run from the station files a recorder serves."""

    def __init__(self, stations: Sequence[AnyStation]) -> None:
        self._stations = {station.station_id: station for station in stations}

    def of(self, summary: RunSummary) -> RunLimits:
        """The program's limits; a station's sensor range without the program; else the
        contract's range."""
        station = self._stations.get(summary.station)
        if station is None:
            return RunLimits(
                CONTRACT_LIMITS.torque_limit_nm,
                None,
                f"no station file for {summary.station}: the contract DBC's torque range",
            )
        sensor_top = torque_top_nm(station.sensor_range)
        if not isinstance(station, LoadedStation):  # a controller's psets carry no limits
            return RunLimits(
                sensor_top,
                None,
                f"{station.path.name} is a controller station: the contract's torque range",
            )
        try:
            program = station.config.program(summary.program_id)
        except KeyError:
            return RunLimits(
                sensor_top,
                None,
                f"{station.path.name} has no program {summary.program_id}: its DBC's torque range",
            )
        return RunLimits(
            min(program.max_torque_nm, sensor_top),
            program.max_time_s,
            f"program {program.id} of {station.path.name}, max_torque_nm",
        )
