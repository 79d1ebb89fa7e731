"""One recorded run, read back for the post-mortem report: traces, events, model.

:func:`read_run` makes one pass over an MCAP recording (damaged files too, see
:mod:`recording_reader`) and keeps the samples, stick-slip events and stop
decisions of one run, and the file's metadata records. When the file carries
the joint (``joint``) and the program's motor speed (``program``), it also
builds the paper's analytical :class:`~shared.model.JointModel` and the shift
from run time to model time (:class:`ModelClock`).

Run time counts from the run's first sample (``Sample.time_ns``), the clock of
every panel. Model time t starts at the untwisted, unloaded joint (φ_m =
φ̇_m t), which a recording never sees: like the paper's 0.15 s shift of
Section 5.2, we anchor the two at the first plateau. The plateau F_1 is left
when sticking breaks at the first peak, so t(F_1) (eqs. 16, 27 solved for t,
:meth:`JointModel.time_at_force_s`) is the model time of that peak. Without
force, the first peak torque anchors them instead (:meth:`time_at_torque_s`).

A run a tool controller tightened (its recording holds the controller's
result: :mod:`.controller_marks`) gets no model: the joint and program
records of its file are the station file's, not what the controller
tightened; the panels draw the controller's own windows and target instead.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.records import Message, Metadata

from shared.config import JointConfig
from shared.contract import (
    ControllerResult,
    RunClock,
    Sample,
    StageDecision,
    StickSlipEvent,
    StopDecision,
    TighteningResult,
    channels,
    decode,
)
from shared.errors import InputError
from shared.model import JointConstants, JointModel
from shared.offline.post_mortem.controller_marks import ControllerMarks
from shared.recordings.mcap import SAMPLE_SCHEMA, RecordingScan

LOG = logging.getLogger(__name__)

EVENT_SCHEMA = channels.EVENTS.schema_name
DECISION_SCHEMA = channels.DECISION.schema_name
STAGE_SCHEMA = channels.STAGE.schema_name
RESULT_SCHEMA = channels.RESULTS.schema_name
CONTROLLER_SCHEMA = channels.CONTROLLER.schema_name
#: why a controller's run has no model (the caption says it)
CONTROLLER_NO_MODEL = (
    "a controller's run: the joint and program in its file are the station file's, "
    "not what the controller tightened"
)


@dataclass(frozen=True, slots=True)
class ModelClock:
    """Run time (s since the first sample) <-> model time t (s since the unloaded joint)."""

    offset_s: float  # t = run time + offset_s
    anchor: str  # what anchors the two clocks, for the caption

    def model_time_s(self, run_time_s: Any) -> Any:
        return run_time_s + self.offset_s


@dataclass(slots=True)
class RecordedRun:
    """The messages of one run of one file, in file order, and what the file says of it."""

    source: Path
    run_id: int
    samples: list[Sample]
    events: list[StickSlipEvent]
    decisions: list[StopDecision]
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    complete: bool = True
    joint: JointConfig | None = None
    motor_speed_rad_s: float | None = None
    model_missing: str = ""  # why there is no model ("" when there is one)
    state: str = ""  # RecordingScan.describe() of the source: complete, or what was lost
    runs_in_file: list[int] = field(default_factory=list)  # every run with samples in the file
    controller: ControllerMarks | None = None  # the controller's windows and target, if its run
    stages: list[StageDecision] = field(default_factory=list)  # a final stage's commands

    @property
    def t0_ns(self) -> int:
        return self.samples[0].time_ns

    def run_time_s(self, time_ns: int) -> float:
        """Seconds since the run's first sample."""
        return RunClock(self.t0_ns).seconds(time_ns)

    @property
    def has_force(self) -> bool:
        return any(s.force_n is not None for s in self.samples)

    def model(self) -> JointModel | None:
        if self.controller is not None or self.joint is None or self.motor_speed_rad_s is None:
            return None
        return JointModel(JointConstants.of(self.joint), self.motor_speed_rad_s)

    def model_clock(self, model: JointModel) -> ModelClock | None:
        """The shift of run time to model time, anchored at the first plateau (or peak)."""
        for event in self.events:
            if event.plateau_force_n is not None and event.plateau_force_n > 0.0:
                t_model = float(model.time_at_force_s(event.plateau_force_n))
                return ModelClock(
                    t_model - self.run_time_s(event.time_ns),
                    f"t(F_{event.index} = {event.plateau_force_n / 1e3:.1f} kN), eqs. 16, 27",
                )
        if self.events and self.events[0].peak_torque_nm > 0.0:
            first = self.events[0]
            t_model = float(model.time_at_torque_s(first.peak_torque_nm))
            return ModelClock(
                t_model - self.run_time_s(first.time_ns),
                f"t(T_max,1 = {first.peak_torque_nm:.0f} Nm), eqs. 19, 27",
            )
        return None


def read_run(source: Path, run_id: int | None = None) -> RecordedRun:
    """The run ``run_id`` of ``source`` (default: the run with the most samples)."""
    scan = RecordingScan(source)
    metadata: dict[str, dict[str, str]] = {}
    samples: list[Sample] = []
    events: list[StickSlipEvent] = []
    decisions: list[StopDecision] = []
    stages: list[StageDecision] = []
    results: list[TighteningResult] = []
    controllers: list[ControllerResult] = []
    kept: dict[str, tuple[type, list[Any]]] = {
        SAMPLE_SCHEMA: (Sample, samples),
        EVENT_SCHEMA: (StickSlipEvent, events),
        DECISION_SCHEMA: (StopDecision, decisions),
        STAGE_SCHEMA: (StageDecision, stages),
        RESULT_SCHEMA: (TighteningResult, results),
        CONTROLLER_SCHEMA: (ControllerResult, controllers),
    }
    undecodable = 0
    for record in scan.records():
        if isinstance(record, Metadata):
            metadata[record.name] = dict(record.metadata)
            continue
        if not isinstance(record, Message):
            continue
        channel = scan.channels.get(record.channel_id)
        schema = scan.schemas.get(channel.schema_id) if channel is not None else None
        wanted = kept.get(schema.name) if schema is not None else None
        if wanted is None:
            continue
        message_type, messages = wanted
        try:
            messages.append(decode(message_type, record.data))
        except InputError:
            undecodable += 1
    if undecodable:
        LOG.warning("%s: %d messages could not be decoded, left out", source, undecodable)
    counts: dict[int, int] = {}
    for sample in samples:
        counts[sample.run_id] = counts.get(sample.run_id, 0) + 1
    run_id = _chosen_run(source, counts, run_id, scan.damage)
    samples = [s for s in samples if s.run_id == run_id]
    run = RecordedRun(
        source,
        run_id,
        samples,
        [e for e in events if e.run_id == run_id],
        [d for d in decisions if d.run_id == run_id],
        metadata,
        scan.complete,
        state=scan.describe(),
        runs_in_file=sorted(counts),
        stages=[d for d in stages if d.run_id == run_id],
    )
    run.joint, run.motor_speed_rad_s, run.model_missing = _model_inputs(metadata)
    run.controller = ControllerMarks.of(
        next((r for r in reversed(results) if r.run_id == run_id), None),
        next((c for c in reversed(controllers) if c.run_id == run_id), None),
    )
    if run.controller is not None:
        run.model_missing = CONTROLLER_NO_MODEL
    return run


def _chosen_run(
    source: Path, counts: dict[int, int], run_id: int | None, damage: str | None
) -> int:
    """``run_id`` if the file has samples of it, else the run with the most samples."""
    if not counts:
        raise InputError(f"{source}: no samples to plot{'' if damage is None else f' ({damage})'}")
    if run_id is None:
        return max(counts, key=counts.__getitem__)
    if run_id not in counts:
        known = ", ".join(str(run) for run in sorted(counts))
        raise InputError(f"{source}: no samples of run {run_id} (runs in the file: {known})")
    return run_id


def _model_inputs(
    metadata: dict[str, dict[str, str]],
) -> tuple[JointConfig | None, float | None, str]:
    """Joint and motor speed from the metadata records; the reason when either is missing."""
    joint: JointConfig | None = None
    speed: float | None = None
    missing: list[str] = []
    flat = metadata.get("joint")
    if flat:
        try:
            joint = JointConfig.model_validate(_unflatten(flat))
        except ValueError as err:
            LOG.warning("joint metadata not usable: %s", err)
            missing.append("joint metadata unusable")
    else:
        missing.append("no joint metadata")
    try:
        speed = float(metadata.get("program", {})["motor_speed_rad_s"])
    except (KeyError, ValueError):
        missing.append("no program motor speed")
    else:
        if speed <= 0.0:
            speed = None
            missing.append("motor speed not positive")
    return joint, speed, ", ".join(missing)


def _unflatten(flat: dict[str, str]) -> dict[str, Any]:
    """``{"a.b": "1.5"}`` -> ``{"a": {"b": "1.5"}}``; empty strings (None) are left out."""
    nested: dict[str, Any] = {}
    for key, value in flat.items():
        if value == "":
            continue
        *parents, name = key.split(".")
        target = nested
        for parent in parents:
            target = target.setdefault(parent, {})
        target[name] = value
    return nested
