"""The messages boltwatch services exchange on zenoh (the payload contracts).

Each message is a frozen dataclass; on the wire it is one JSON object (UTF-8)
whose fields are exactly the dataclass fields, described by the JSON schema
that :func:`shared.contract.codec.json_schema` derives from the dataclass (the same
schema goes into MCAP, so Foxglove and the mcap CLI decode recordings with no
code of ours). Times are integer nanoseconds since the Unix epoch (``*_ns``)
or float seconds since the start of the run (``*_s``); units are in names.
Every field is bounded (times, ids and counts from 0, station ids a key
chunk, figures finite, texts of limited length): the aliases of
:mod:`shared.contract.message_fields` say how, and the decoder refuses the rest
(``__pydantic_config__``: :data:`~shared.contract.message_fields.WIRE_CONFIG`). Which
channel carries which message, who puts it and how: :mod:`shared.contract.channels`.

What tool controllers say (a controller's result, its tool data and alarms, a
controller bridge's counters) is in :mod:`shared.contract.controller_messages` and
imported from here as every other message. A multi-spindle cycle's common result
(:class:`~shared.contract.cycle_messages.CycleResult`) is in
:mod:`shared.contract.cycle_messages`.
What the line says of the part at a station (:class:`PartScan`) is in
:mod:`shared.contract.part_messages`, imported from here too; what a station
commands a tool that runs a final stage (:class:`StageDecision`), in
:mod:`shared.contract.stage_messages`; who acknowledged an alert (:class:`AlertAck`),
in :mod:`shared.contract.alert_messages`; what the recorder forecasts of a tool's
service (:class:`WearForecast`), in :mod:`shared.contract.wear_messages`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any, Literal

from pydantic import SerializerFunctionWrapHandler, model_serializer

from shared.contract.alert_messages import (  # noqa: F401  (re-exported: one import for every message)
    AlertAck,
    AlertAction,
    AlertSource,
)
from shared.contract.controller_messages import (  # noqa: F401  (re-exported: one import for every message)
    AlarmKind,
    BridgeStats,
    ControllerAlarm,
    ControllerFunction,
    ControllerResult,
    ControllerStep,
    RunOperation,
    ToolData,
)
from shared.contract.message_fields import (
    WIRE_CONFIG,
    Count,
    Id,
    Measured,
    SpindleNumber,
    StationId,
    TimeNs,
    without_unset_spindle,
)
from shared.contract.part_messages import (  # noqa: F401  (re-exported: one import for every message)
    PartScan,
    PartSource,
)
from shared.contract.spool_messages import (  # noqa: F401  (re-exported: one import for every message)
    SeqRange,
    SpoolAck,
    SpoolFiled,
    SpoolStats,
)
from shared.contract.stage_messages import (  # noqa: F401  (re-exported: one import for every message)
    FEATURE_STAGES,
    StageCommandCode,
    StageCommandName,
    StageDecision,
    StageReason,
    StageReasonName,
    ToolCommandsName,
    ToolStageCode,
    ToolStageName,
)
from shared.contract.wear_messages import WearForecast  # re-exported too

ToolStateName = Literal["idle", "running", "done", "aborted"]
StopReasonName = Literal[
    "unspecified",
    "plateau_closest",
    "target_reached",
    "intensity_limit",
    "constant_out_of_band",
    "torque_limit",
    "force_limit",
    "angle_limit",
    "input_fault",
]


class ToolRunState(IntEnum):
    """``State`` of the CAN ``ToolStatus`` message (VAL_ table of the DBC)."""

    IDLE = 0
    RUNNING = 1
    DONE = 2
    ABORTED = 3


class StopReason(IntEnum):
    """``Reason`` of the CAN ``StopCommand`` message (VAL_ table of the DBC)."""

    UNSPECIFIED = 0
    PLATEAU_CLOSEST = 1  # eqs. 64/65: the next plateau would be farther from target
    TARGET_REACHED = 2  # a joint with no stick-slip reached its target
    INTENSITY_LIMIT = 3  # eq. 70
    CONSTANT_OUT_OF_BAND = 4  # eq. 71
    TORQUE_LIMIT = 5
    FORCE_LIMIT = 6
    ANGLE_LIMIT = 7
    INPUT_FAULT = 8  # sensor input unusable for long enough that going on would be blind


@dataclass(frozen=True, slots=True)
class Sample:
    """One 1 kHz sample: a ToolSensors frame paired with its JointSensors frame."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    sequence: Count  # sample index within the run (the 16-bit CAN Counter, unrolled)
    time_ns: TimeNs  # CAN receive time of the frame that completed the sample
    torque_nm: Measured
    angle_deg: Measured
    force_n: Measured | None  # None on torque-only stations or when JointSensors was lost
    # the sample's time on the tool's own clock, seconds since the run's first sample
    # (sequence / the contract's 1 kHz; a controller's own time for an import): what the
    # predictor decides on, free of receive jitter. None: unknown, the receive time stands in
    time_s: float | None = None


@dataclass(frozen=True, slots=True)
class SampleBatch:
    """A station's samples of the last few milliseconds, in order, with the events found in
    them: what the line records of an edge station.

    The acquisition of an edge station sends its samples toward the line in
    batches (:data:`shared.contract.channels.SAMPLE_BATCHES`, one every
    :data:`shared.runtime.sample_batching.BATCH_PERIOD_S` at most, at most
    :data:`shared.runtime.sample_batching.MAX_BATCH_SAMPLES` samples, never two runs): one
    zenoh message per batch instead of one per sample. The stick-slip events its
    predictor found while the batch was in progress, and their intensities, ride
    in it after the samples (an event found when no batch is in progress goes
    alone on ``events``). Every message in it names the batch's station. The
    recorder writes each sample, event and intensity as its own MCAP message on
    ``boltwatch/<station>/samples``, ``events`` and ``intensity``, as if it had
    come alone. Bounded by the payload's size (64 KiB: about 400 samples).
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs  # when the station's publisher sent it
    samples: list[Sample]
    events: list[StickSlipEvent] = field(default_factory=list)  # found in these samples
    intensities: list[Intensity] = field(default_factory=list)  # one per event, in order


@dataclass(frozen=True, slots=True)
class ToolState:
    """The tool's run state (CAN ToolStatus), published when it changes."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    tool_id: Id
    program_id: Id
    state: ToolStateName
    time_ns: TimeNs
    # done / aborted: the StopCommand boltwatch sent the tool in this run (its reason);
    # None: none went out, the tool stopped by itself (its own shutoff or limits)
    stop_command: StopReasonName | None = None
    # what the station may command the tool in this run: "stop", or "staged" (a final
    # stage and pulses: its controller said it takes StageCommand); None: not said (a
    # controller bridge, a recording made before stages existed): stop
    commands: ToolCommandsName | None = None
    # running, on a staged tool: the stage it runs (ToolStage); a change is a new ToolState
    stage: ToolStageName | None = None
    pulses: Count = 0  # pulses the tool has run in this run
    # a multi-spindle station's run: its spindle (1..N) and the sync id of the cycle it is a
    # run of (the controller's; every spindle's run of the cycle has it); None: a station
    # of one spindle (shared/contract/cycle_messages.py)
    spindle: SpindleNumber | None = None
    sync_id: Id | None = None

    @model_serializer(mode="wrap")
    def _wire(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        return without_unset_spindle(handler(self))


@dataclass(frozen=True, slots=True)
class BusStats:
    """Counters of the acquisition since it started; faults are counted, never fatal."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs
    frames: Count
    samples: Count
    unknown_ids: Count
    wrong_length: Count
    decode_errors: Count
    error_frames: Count
    receive_errors: Count  # the bus driver raised on receive (bus-off, link down)
    counter_gaps: Count  # times the Counter skipped ahead
    missed_samples: Count  # samples lost in those gaps
    counter_faults: Count  # repeated or backwards Counters, frames dropped
    unpaired: Count  # ToolSensors published without a JointSensors partner
    orphans: Count  # JointSensors dropped: no ToolSensors partner in time
    stop_commands: Count
    unsent_samples: Count = 0  # published while the session had no router: lost, counted
    late_decisions: Count = 0  # stop decisions for a run the tool was no longer running
    repeated_runs: Count = 0  # ToolStatus starting a run id that had started already: ignored
    started_ns: TimeNs = 0  # when this acquisition process started: a new value, a new process
    bad_decisions: Count = 0  # decision payloads refused (not a valid StopDecision): no stop
    # what the station may command its tool in the next run: stop, or staged (a final
    # stage: the DBC, the station file and the tool controller all allow it); why not
    tool_commands: ToolCommandsName = "stop"
    tool_commands_note: str = ""
    stage_commands: Count = 0  # StageCommands sent
    refused_stages: Count = 0  # a final stage's commands for a run whose tool runs stop only


@dataclass(frozen=True, slots=True)
class Prediction:
    """A predicted stick-slip event, ``horizon`` events ahead (1 = the next)."""

    __pydantic_config__ = WIRE_CONFIG

    horizon: Count
    time_s: float
    peak_torque_nm: float
    plateau_force_n: float | None


@dataclass(frozen=True, slots=True)
class StickSlipEvent:
    """One detected stick-slip event j with its figures (paper Fig. 3, eqs. 31-33, 66-68)."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    index: Count  # j, counting from 1 within the run
    time_ns: TimeNs  # receive time of the peak sample
    time_s: float  # time of the torque peak since run start
    peak_torque_nm: float  # T_max,j
    min_torque_nm: float | None  # T_min,j after the slip
    torque_drop_nm: float | None  # ΔT_j
    plateau_force_n: float | None  # F_j, the plateau the peak belongs to
    force_step_n: float | None  # ΔF_j
    period_s: float | None  # Δt_j to the previous peak
    f_ss_hz: float | None
    k1: float | None
    k2: float | None
    k3: float | None
    intensity: float | None  # I_j, eq. 67
    process_intensity: float  # I_process so far, eq. 68
    predictions: list[Prediction] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class Intensity:
    """Vibration intensity: of the last event and of the process so far (eqs. 67, 68)."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    time_ns: TimeNs
    event_intensity: float
    process_intensity: float


@dataclass(frozen=True, slots=True)
class StopDecision:
    """The predictor's decision to stop the tool now, with its reason."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    time_ns: TimeNs  # receive time of the sample at which it was decided
    time_s: float  # the same, since run start
    reason: StopReasonName
    detail: str
    torque_nm: Measured  # NaN: no usable torque (an input_fault after non-finite ones)
    force_n: float | None
    predicted_force_n: float | None  # the force the stop is predicted to land on (force target)
    decided_ns: TimeNs  # wall clock when the decision was published (a replay: the sample's time)
    predicted_torque_nm: float | None = None  # the torque it lands on (torque target)
    # True: decided on a replay of a run a tool controller stopped (``boltwatch import``),
    # never acted on; False (the default, also when absent on the wire): a live decision
    advisory: bool = False


@dataclass(frozen=True, slots=True)
class RunSummary:
    """One tightening run, start to end, as the predictor saw it."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    tool_id: Id
    program_id: Id
    tool_state: ToolStateName  # done or aborted
    target_force_n: float | None
    target_torque_nm: float | None
    reached_force_n: float | None
    reached_torque_nm: float
    error_pct: float | None  # (reached - target) / target, of force if measured else torque
    events: Count
    # what stopped the tool: the reason of the StopCommand that went out in this run (as the
    # acquisition reported it); None: the tool stopped by itself
    stop_reason: StopReasonName | None
    process_intensity: float
    samples: Count
    started_ns: TimeNs
    ended_ns: TimeNs
    # the predictor's decision when it did not stop the tool (it came after the tool had
    # stopped, or its StopCommand never went out): a late decision, not the stop reason
    late_decision: StopReasonName | None = None
    # the angle of the run's last measured sample (deg since the run started); None: unknown
    reached_angle_deg: float | None = None
    # a loosening (an imported controller run turning the tool back) is no tightening: the
    # wear ledger counts its intensity, not the run among the tool's tightenings
    operation: RunOperation = "tightening"
    # what the station could command the tool in this run ("staged": a final stage and
    # pulses; None: not said, stop only); a final stage: when it began, seconds since the
    # run's start (None: none ran), and the pulses back to the target the run took
    commands: ToolCommandsName | None = None
    final_stage_s: float | None = None
    pulses: Count = 0
    # a multi-spindle station's run: its spindle and its cycle's sync id (as its ToolState);
    # None: a station of one spindle
    spindle: SpindleNumber | None = None
    sync_id: Id | None = None

    @model_serializer(mode="wrap")
    def _wire(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        return without_unset_spindle(handler(self))


@dataclass(frozen=True, slots=True)
class RecorderStats:
    """The recorder's view of one station, once a second: is it keeping up and writing?"""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs
    messages: Count  # messages of this station written since the recorder started
    lag_p50_ms: float | None  # receive time minus acquisition time of samples, last second
    lag_max_ms: float | None
    write_errors: Count  # failed writes (disk full, read-only folder, ...) since start
    last_error: str | None  # the newest write error, None when writing is healthy
    recording: bool  # False while the recordings folder cannot be written
    missing_samples: Count = 0  # published by the acquisition (BusStats) but never received
    # payloads on a message key refused by the decoder (bad JSON, a wrong type, a value out of
    # its bounds, a time ahead of its arrival): recorded raw on the key's raw channel
    bad_payloads: Count = 0
    # RunSummaries of this station the wear ledger refused (beyond what the run can carry)
    refused_summaries: Count = 0
    # runs (of every station) waiting in memory for the wear ledger (failing or broken)
    waiting_summaries: Count = 0
    # results (of every station) waiting in memory for the results store (failing)
    waiting_results: Count = 0
    # the station's line, as its station file names it (``[station] line``; "": none)
    line: str = ""
    # this station's quality alerts active now, newest first (each is put once, when it starts:
    # a status that listens later learns of it here)
    quality_alerts: list[QualityAlert] = field(default_factory=list)
    # run files of this station the retention policy ([retention]) deleted since the recorder
    # started
    recordings_deleted: Count = 0
    # run files of this station past their time that the last retention pass kept because
    # their results are not in the results store
    recordings_kept_unstored: Count = 0
    # the plant of the station's line, as its station file names it (``[station] plant``;
    # "": none)
    plant: str = ""
    # the station's name for people, as its station file names it (``[station] name``; "":
    # none, its id is shown)
    station_name: str = ""
    # the tools (whose newest run was at this station) forecast due within the recorder's
    # largest horizon now, the soonest first: each as last forecast (put once per horizon on
    # wear/forecast: a status that listens later learns of them here)
    wear_forecasts: list[WearForecast] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class PredictorStats:
    """The predictor's counts for one served station since it started, once a second."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs
    started_ns: TimeNs  # when this predictor process started: a new value, a new process
    # samples, tool states and part scans refused (not a valid message, or naming another
    # station)
    bad_payloads: Count
    # samples of ended runs the core could not use: a bad time (NaN, out of order, a jump of
    # more than its MAX_JUMP_S) or torque (NaN, outside the station's sensor range)
    bad_samples: Count
    samples_without_run: Count  # samples of a run that was not running here: dropped
    unfinished_runs: Count  # runs whose end never arrived (a network outage): no summary
    repeated_runs: Count  # ToolStates starting a run id that had started already: ignored


@dataclass(frozen=True, slots=True)
class WearAlert:
    """A tool has taken its service threshold of vibration intensity since its last service."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    tool_id: Id
    time_ns: TimeNs
    intensity_since_service: float  # Σ I_process of the runs since the last service (eq. 69)
    threshold: float
    runs_since_service: Count
    last_service_ns: TimeNs | None


#: why a quality alert: a rolling Cpk below ``quality.cpk_min``; ``quality.nok_run`` NOKs
#: in a row; ``quality.nok_max`` NOKs among the last ``quality.nok_window`` results
QualityAlertKind = Literal["cpk_low", "nok_run", "nok_rate"]
#: the figure of a ``cpk_low`` alert (None for the NOK kinds: they count verdicts)
QualityFigure = Literal["torque", "angle", "preload"]


@dataclass(frozen=True, slots=True)
class QualityAlert:
    """A program's results at a station went out of control (or came back: ``active`` False).

    Put by the recorder when the condition starts, once; again when it has
    cleared (``active`` False) and again if it returns. ``value`` against
    ``limit``: the Cpk and ``quality.cpk_min``, the NOKs in a row and
    ``quality.nok_run``, the NOKs among the last ``runs`` and ``quality.nok_max``.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    program_id: Id
    time_ns: TimeNs  # when the result that started (or cleared) it ended
    kind: QualityAlertKind
    figure: QualityFigure | None
    value: float
    limit: float
    runs: Count  # the results considered
    active: bool
    text: str  # the alert in words


#: where a figure ended against its window; ``not_judged``: no window, or no value
FigureStatus = Literal["low", "ok", "high", "not_judged"]
#: the run's verdict, as every tightening system of a plant says it
Verdict = Literal["OK", "NOK"]
#: a step's status as its controller gave it; ``not_judged``: it gave none
StepStatus = Literal["OK", "NOK", "not_judged"]
#: who made a result: the live predictor (``RunSummary`` + the program's windows), a
#: controller on the line (its own result, live), ``boltwatch import`` (a controller's file)
ResultSource = Literal["predictor", "controller", "import"]


@dataclass(frozen=True, slots=True)
class JudgedFigure:
    """A run's final figure (torque, angle or preload), its window and where it ended."""

    __pydantic_config__ = WIRE_CONFIG

    value: float | None  # None: not measured
    min: float | None  # the window's bounds; None: no bound on that side
    max: float | None
    status: FigureStatus


@dataclass(frozen=True, slots=True)
class ResultStep:
    """One step of a controller's program in a result: what ended it, and its status."""

    __pydantic_config__ = WIRE_CONFIG

    name: str  # as the controller names it, e.g. "Tightening 1.4"
    function: str  # the tightening function that ended it ("TF Torque"); "" when none
    nominal: float | None  # that function's nominal and actual value (its own unit)
    actual: float | None
    status: StepStatus


@dataclass(frozen=True, slots=True)
class TighteningResult:
    """The result of one tightening: OK or NOK against its program's windows.

    What a plant's quality report speaks: the final torque, angle and preload
    each with its window and status, the verdict and why, the steps of a
    controller's program, and boltwatch's own figures of the run (stick-slip
    events, process intensity, what stopped the tool). One per run on
    ``boltwatch/<st>/results``, made by :mod:`shared.quality.verdict`.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    tightening_id: Id  # the tool controller's id of the tightening (the run id of our tools)
    run_id: Id
    tool_id: Id
    program_id: Id
    program_name: str  # "" when unknown
    time_ns: TimeNs  # when the run ended
    # the part (work piece, VIN) tightened: a controller's VIN, or the part the line scanned
    # (boltwatch/<st>/part) before the run started; None: unknown
    part_id: str | None
    batch_counter: Count | None  # the run's count within its batch; None: no batch known
    final_torque_nm: JudgedFigure
    final_angle_deg: JudgedFigure  # since the run started (a controller: its last step's angle)
    final_force_n: JudgedFigure  # the preload
    result: Verdict
    nok_reasons: str  # why NOK, short texts separated by "; "; "" when OK
    stop_reason: StopReasonName | None  # the StopCommand boltwatch sent; None: the tool stopped
    events: Count | None  # stick-slip events; None: no predictor saw the run
    process_intensity: float | None  # I_process, eq. 68; None: no predictor saw the run
    source: ResultSource
    steps: list[ResultStep] = field(default_factory=list)  # a controller's; empty live
    # where the part a live run names came from (:data:`PartSource`: scanned before the run,
    # restored from the line when the predictor started, unknown); None: not said (a result
    # of a controller, which names its own VIN, or one made before this field)
    part_source: PartSource | None = None
    # a final stage (a staged tool): the pulses back to the target the run took (a pulse
    # won back a slip drop lost during the halt); None: the run had no final stage
    pulses: Count | None = None
    # a multi-spindle station's run: its spindle (1..N) and the sync id of its cycle, whose
    # common result is a CycleResult on ``cycles``; None: a station of one spindle
    spindle: SpindleNumber | None = None
    sync_id: Id | None = None

    @model_serializer(mode="wrap")
    def _wire(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        return without_unset_spindle(handler(self))
