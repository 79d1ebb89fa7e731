"""What ``boltwatch status`` saw of each station: pure aggregation.

The command (``services/cli/commands/status.py``, and the line's page
``services/dashboard/``) owns the zenoh session; it
feeds this module what arrives, and asks it for a report at the end of the
listening window. Nothing here knows about zenoh or clocks: receive times and
"now" are passed in (integer nanoseconds since the Unix epoch). The report is
printed by :mod:`services.cli.station_status_text` (for a person) or
:func:`to_json` (for a program).

Per station:

- services alive: the tokens ``boltwatch/<st>/health/<service>``, its own first;
- sample rate: samples received per second over the window (one per Sample
  message of a line-placed station, every sample of an edge station's
  SampleBatch), and, when
  two or more BusStats arrived, the acquisition's own count (``samples``
  delta over ``time_ns`` delta) -- the second tells a slow link from a slow bus;
- bus faults: from the latest BusStats (:mod:`shared.line_status.status_bus`);
- last run: the latest ToolState; failing that the run of the latest Sample
  (then running), failing that the latest RunSummary;
- last decision, last run summary: the latest of each, with its age;
- last result: the latest TighteningResult, its OK/NOK and why
  (:mod:`shared.line_status.status_last_result`);
- recorder: the latest RecorderStats (``boltwatch/<st>/recorder``, once a
  second): lag of samples into the recorder (p50/max over its last second,
  None when no samples came), messages written, samples the acquisition
  published that never reached the recorder, payloads it refused (recorded
  raw), write errors and whether it is recording, run summaries the wear
  ledger refused and runs waiting in memory for a failing or broken ledger
  (its error is the ``last_error``);
- predictor: the latest PredictorStats (``boltwatch/<st>/predictor``, once a
  second): payloads it refused, samples its core could not use, samples of
  no running run, runs whose end never arrived;
- a controller bridge's link, faults and newest active alarm, and its services
  (``kind`` "bridge"), for a station with one (:mod:`shared.line_status.status_bridge`);
- the newest active quality alert of the recorder (a program's Cpk or NOKs,
  :mod:`shared.line_status.status_quality_alert`);
- the tools the recorder forecasts due for service soon, the soonest first
  (:mod:`shared.line_status.status_wear_forecast`);
- its spools: what waits for the line's recorder, and an alert when one fills
  or drops (:mod:`shared.line_status.status_spool`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from shared.contract import (
    BusStats,
    PredictorStats,
    RecorderStats,
    RunSummary,
    Sample,
    SampleBatch,
    SpoolStats,
    StopDecision,
    TighteningResult,
    ToolState,
    channels,
    decode,
    keys,
)
from shared.errors import InputError
from shared.line_status.status_bridge import TOPICS as BRIDGE_TOPICS
from shared.line_status.status_bridge import (
    BridgeSeen,
    BridgeStatus,
    bridge_status,
    is_bridge_station,
    station_services,
)
from shared.line_status.status_bus import BusHealth, bus_health, bus_rate
from shared.line_status.status_last_result import LastResult, last_result
from shared.line_status.status_quality_alert import TOPIC as QUALITY_TOPIC
from shared.line_status.status_quality_alert import (
    ActiveQualityAlert,
    QualitySeen,
    quality_alert,
)
from shared.line_status.status_spool import TOPIC as SPOOL_TOPIC
from shared.line_status.status_spool import SpoolStatus, spool_status
from shared.line_status.status_spool import take as take_spool
from shared.line_status.status_wear_forecast import TOPIC as FORECAST_TOPIC
from shared.line_status.status_wear_forecast import DueSoon, ForecastsSeen, due_soon

#: The services of a CAN station, in display order; others are shown if alive.
KNOWN_SERVICES = ("acquisition", "predictor", "recorder", "rig")

_NS = 1_000_000_000

#: topics of which only the latest message counts: topic -> (its message type, _Seen field)
_LATEST: dict[str, tuple[type, str]] = {
    channels.TOOL.topic: (ToolState, "tool"),
    channels.DECISION.topic: (StopDecision, "decision"),
    channels.RUNS.topic: (RunSummary, "summary"),
    channels.RESULTS.topic: (TighteningResult, "result"),
}


@dataclass
class _Seen:
    """Everything received from one station during the window."""

    services: set[str] = field(default_factory=set)
    samples: int = 0
    # the latest sample: its payload (one message per sample: decoded once, at report time)
    # or, from a batch (decoded already to be counted), the sample itself
    last_sample: bytes | Sample | None = None
    first_bus: BusStats | None = None
    bus: BusStats | None = None
    bus_received_ns: int = 0
    tool: ToolState | None = None
    decision: StopDecision | None = None
    summary: RunSummary | None = None
    result: TighteningResult | None = None
    recorder: RecorderStats | None = None
    recorder_received_ns: int = 0
    predictor: PredictorStats | None = None
    predictor_received_ns: int = 0
    bridge: BridgeSeen = field(default_factory=BridgeSeen)
    quality: QualitySeen = field(default_factory=QualitySeen)
    forecasts: ForecastsSeen = field(default_factory=ForecastsSeen)
    spools: dict[str, tuple[SpoolStats, int]] = field(default_factory=dict)
    unreadable: int = 0


@dataclass(frozen=True)
class LastRun:
    run_id: int
    state: str  # idle | running | done | aborted
    tool_id: int | None
    program_id: int | None
    source: str  # "tool" (ToolState), "samples" (inferred: running), "runs" (RunSummary)


@dataclass(frozen=True)
class LastDecision:
    run_id: int
    reason: str
    detail: str
    age_s: float  # since the predictor published it (its wall clock)


@dataclass(frozen=True)
class LastSummary:
    run_id: int
    unit: str  # "N" (force target) or "Nm" (torque target)
    target: float | None
    reached: float | None
    error_pct: float | None
    stop_reason: str | None  # None: the tool stopped by itself
    tool_state: str
    events: int
    age_s: float  # since the run ended


@dataclass(frozen=True)
class RecorderHealth:
    """The recorder's own view of the station (latest RecorderStats)."""

    recording: bool  # False while the recordings folder cannot be written
    lag_p50_ms: float | None  # sample receive time in the recorder minus CAN time
    lag_max_ms: float | None
    messages: int  # written for this station since the recorder started
    missing_samples: int  # published by the acquisition, never received by the recorder
    write_errors: int
    last_error: str | None
    age_s: float  # since the latest RecorderStats was received
    refused_summaries: int = 0  # RunSummaries the wear ledger refused (beyond their bound)
    waiting_summaries: int = 0  # runs waiting in the recorder's memory for the wear ledger
    waiting_results: int = 0  # results waiting in the recorder's memory for the results store
    plant: str = ""  # the plant of the station's line, as the recorder's station file names it
    line: str = ""  # the station's line, as the recorder's station file names it
    station_name: str = ""  # the station's name for people, as that file names it
    bad_payloads: int = 0  # payloads it refused (recorded raw)
    recordings_deleted: int = 0  # run files the retention policy deleted since it started
    recordings_kept_unstored: int = 0  # past their time, kept: their results are not stored


@dataclass(frozen=True)
class PredictorHealth:
    """What the predictor could not use at the station (latest PredictorStats)."""

    bad_payloads: int  # samples and tool payloads refused
    bad_samples: int  # samples of ended runs its core dropped (bad time or torque)
    samples_without_run: int
    unfinished_runs: int
    age_s: float  # since the latest PredictorStats was received


@dataclass(frozen=True)
class StationStatus:
    station: str
    services: dict[str, bool]
    samples_per_s: float  # Sample messages received per second of the window
    bus_samples_per_s: float | None  # from BusStats deltas; None: fewer than two
    bus: BusHealth | None
    last_run: LastRun | None
    last_decision: LastDecision | None
    last_summary: LastSummary | None
    recorder: RecorderHealth | None  # None: no RecorderStats in the window
    unreadable_messages: int
    predictor: PredictorHealth | None = None  # None: no PredictorStats in the window
    last_result: LastResult | None = None  # None: no TighteningResult in the window
    bridge: BridgeStatus | None = None  # None: no controller bridge spoke in the window
    quality_alert: ActiveQualityAlert | None = None  # None: none active in the window
    kind: str = "can"  # "bridge": a controller bridge's station (services: its own)
    spools: list[SpoolStatus] = field(default_factory=list)  # its spools heard in the window
    #: the tools forecast due for service soon (the recorder's horizon), the soonest first
    wear_forecasts: list[DueSoon] = field(default_factory=list)


@dataclass(frozen=True)
class StatusReport:
    endpoint: str
    listened_s: float
    stations: list[StationStatus]


class StatusCollector:
    """Accumulates liveliness replies and messages; not thread-safe (the caller locks)."""

    def __init__(self) -> None:
        self._stations: dict[str, _Seen] = {}

    def _station(self, station: str) -> _Seen:
        seen = self._stations.get(station)
        if seen is None:
            seen = self._stations[station] = _Seen()
        return seen

    def alive(self, key: str) -> None:
        """A liveliness token ``boltwatch/<st>/health/<service>`` exists."""
        try:
            station, rest = keys.split_key(key)
        except ValueError:
            return
        topic, _, service = rest.partition("/")
        if topic == keys.HEALTH and service:
            self._station(station).services.add(service)

    def message(self, key: str, payload: bytes, received_ns: int) -> None:
        """One message on ``boltwatch/<st>/<topic>``; unknown topics only mark the station seen."""
        try:
            station, topic = keys.split_key(key)
        except ValueError:
            return
        seen = self._station(station)
        try:
            if topic == channels.SAMPLES.topic:
                # 1 kHz: count only; the latest is decoded once, at report time.
                seen.samples += 1
                seen.last_sample = payload
            elif topic == channels.SAMPLE_BATCHES.topic:  # an edge station's, 20 a second
                batch = decode(SampleBatch, payload)
                if batch.samples:
                    seen.samples += len(batch.samples)
                    seen.last_sample = batch.samples[-1]
            elif topic == channels.BUS.topic:
                stats = decode(BusStats, payload)
                if seen.first_bus is None:
                    seen.first_bus = stats
                seen.bus = stats
                seen.bus_received_ns = received_ns
            elif topic in _LATEST:
                message_type, attribute = _LATEST[topic]
                setattr(seen, attribute, decode(message_type, payload))
            elif topic == channels.RECORDER.topic:
                seen.recorder = decode(RecorderStats, payload)
                seen.quality.take_active(seen.recorder.quality_alerts)
                seen.forecasts.take_current(seen.recorder.wear_forecasts)
                seen.recorder_received_ns = received_ns
            elif topic == channels.PREDICTOR.topic:
                seen.predictor = decode(PredictorStats, payload)
                seen.predictor_received_ns = received_ns
            else:
                _take_other(seen, topic, payload, received_ns)
        except InputError:
            seen.unreadable += 1

    def report(self, endpoint: str, listened_s: float, now_ns: int) -> StatusReport:
        """Every station seen, by name."""
        stations = [
            _status(name, seen, listened_s, now_ns) for name, seen in sorted(self._stations.items())
        ]
        return StatusReport(endpoint=endpoint, listened_s=listened_s, stations=stations)


def _take_other(seen: _Seen, topic: str, payload: bytes, received_ns: int) -> None:
    """A message of a bridge, a quality alert, a wear forecast, a spool's counters (any
    other: nothing)."""
    if topic in BRIDGE_TOPICS:
        seen.bridge.take(topic, payload, received_ns)
    elif topic == QUALITY_TOPIC:
        seen.quality.take(payload)
    elif topic == FORECAST_TOPIC:
        seen.forecasts.take(payload)
    elif topic == SPOOL_TOPIC:
        take_spool(seen.spools, payload, received_ns)


def _status(name: str, seen: _Seen, listened_s: float, now_ns: int) -> StationStatus:
    services = station_services(seen.services, seen.bridge, KNOWN_SERVICES)
    last_sample = _decode_sample(seen.last_sample)
    unreadable = seen.unreadable + (1 if seen.last_sample and last_sample is None else 0)
    return StationStatus(
        station=name,
        services=services,
        samples_per_s=round(seen.samples / listened_s, 1) if listened_s > 0 else 0.0,
        bus_samples_per_s=bus_rate(seen.first_bus, seen.bus),
        bus=bus_health(seen.bus, seen.bus_received_ns, now_ns),
        last_run=_last_run(seen.tool, last_sample, seen.summary),
        last_decision=_last_decision(seen.decision, now_ns),
        last_summary=_last_summary(seen.summary, now_ns),
        recorder=_recorder_health(seen.recorder, seen.recorder_received_ns, now_ns),
        unreadable_messages=unreadable,
        predictor=_predictor_health(seen.predictor, seen.predictor_received_ns, now_ns),
        last_result=last_result(seen.result, now_ns),
        bridge=bridge_status(seen.bridge, now_ns),
        quality_alert=quality_alert(seen.quality, now_ns),
        kind="bridge" if is_bridge_station(seen.services, seen.bridge) else "can",
        spools=spool_status(seen.spools, now_ns),
        wear_forecasts=due_soon(seen.forecasts, now_ns),
    )


def _decode_sample(payload: bytes | Sample | None) -> Sample | None:
    if payload is None or isinstance(payload, Sample):
        return payload
    try:
        return decode(Sample, payload)
    except InputError:
        return None


def _recorder_health(
    stats: RecorderStats | None, received_ns: int, now_ns: int
) -> RecorderHealth | None:
    if stats is None:
        return None
    return RecorderHealth(
        recording=stats.recording,
        lag_p50_ms=stats.lag_p50_ms,
        lag_max_ms=stats.lag_max_ms,
        messages=stats.messages,
        missing_samples=stats.missing_samples,
        write_errors=stats.write_errors,
        last_error=stats.last_error,
        age_s=_age_s(received_ns, now_ns),
        refused_summaries=stats.refused_summaries,
        waiting_summaries=stats.waiting_summaries,
        waiting_results=stats.waiting_results,
        plant=stats.plant,
        line=stats.line,
        station_name=stats.station_name,
        bad_payloads=stats.bad_payloads,
        recordings_deleted=stats.recordings_deleted,
        recordings_kept_unstored=stats.recordings_kept_unstored,
    )


def _predictor_health(
    stats: PredictorStats | None, received_ns: int, now_ns: int
) -> PredictorHealth | None:
    if stats is None:
        return None
    return PredictorHealth(
        bad_payloads=stats.bad_payloads,
        bad_samples=stats.bad_samples,
        samples_without_run=stats.samples_without_run,
        unfinished_runs=stats.unfinished_runs,
        age_s=_age_s(received_ns, now_ns),
    )


def _last_run(
    tool: ToolState | None, sample: Sample | None, summary: RunSummary | None
) -> LastRun | None:
    if tool is not None:
        return LastRun(tool.run_id, tool.state, tool.tool_id, tool.program_id, "tool")
    if sample is not None:
        return LastRun(sample.run_id, "running", None, None, "samples")
    if summary is not None:
        return LastRun(
            summary.run_id, summary.tool_state, summary.tool_id, summary.program_id, "runs"
        )
    return None


def _last_decision(decision: StopDecision | None, now_ns: int) -> LastDecision | None:
    if decision is None:
        return None
    return LastDecision(
        run_id=decision.run_id,
        reason=decision.reason,
        detail=decision.detail,
        age_s=_age_s(decision.decided_ns, now_ns),
    )


def _last_summary(summary: RunSummary | None, now_ns: int) -> LastSummary | None:
    if summary is None:
        return None
    target: float | None
    reached: float | None
    if summary.target_force_n is not None:
        unit, target, reached = "N", summary.target_force_n, summary.reached_force_n
    else:
        unit, target, reached = "Nm", summary.target_torque_nm, summary.reached_torque_nm
    return LastSummary(
        run_id=summary.run_id,
        unit=unit,
        target=target,
        reached=reached,
        error_pct=summary.error_pct,
        stop_reason=summary.stop_reason,
        tool_state=summary.tool_state,
        events=summary.events,
        age_s=_age_s(summary.ended_ns, now_ns),
    )


def _age_s(then_ns: int, now_ns: int) -> float:
    return round((now_ns - then_ns) / _NS, 3)


def to_json(report: StatusReport) -> dict[str, Any]:
    """The report as one JSON-ready object; stations keyed by id."""
    return {
        "endpoint": report.endpoint,
        "listened_s": report.listened_s,
        "stations": {
            status.station: {
                name: value
                for name, value in dataclasses.asdict(status).items()
                if name != "station"
            }
            for status in report.stations
        },
    }
