"""One recorded run, read back for the post-mortem report: traces, events, model.

:func:`read_run` makes one pass over an MCAP recording (damaged files too, see
:mod:`recording_reader`) and keeps the samples, stick-slip events, stop
decisions, a final stage's commands and the result of one run, and the file's
metadata records; :func:`read_run_files` the same over the files of a run
the recorder split (its parts, a second file after a restart), in their order. When the file carries
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
from collections.abc import Sequence
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
    result: TighteningResult | None = None  # the run's result in the file (the last one)
    sources: list[Path] = field(default_factory=list)  # every file read (source: the first)

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
    return read_run_files([source], run_id)


@dataclass
class _Kept:
    """What the files hold of every run, in file order, as they are read."""

    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    samples: list[Sample] = field(default_factory=list)
    events: list[StickSlipEvent] = field(default_factory=list)
    decisions: list[StopDecision] = field(default_factory=list)
    stages: list[StageDecision] = field(default_factory=list)
    results: list[TighteningResult] = field(default_factory=list)
    controllers: list[ControllerResult] = field(default_factory=list)
    undecodable: int = 0

    def read(self, scan: RecordingScan) -> None:
        kept: dict[str, tuple[type, list[Any]]] = {
            SAMPLE_SCHEMA: (Sample, self.samples),
            EVENT_SCHEMA: (StickSlipEvent, self.events),
            DECISION_SCHEMA: (StopDecision, self.decisions),
            STAGE_SCHEMA: (StageDecision, self.stages),
            RESULT_SCHEMA: (TighteningResult, self.results),
            CONTROLLER_SCHEMA: (ControllerResult, self.controllers),
        }
        for record in scan.records():
            if isinstance(record, Metadata):
                self.metadata[record.name] = dict(record.metadata)
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
                self.undecodable += 1


def read_run_files(files: Sequence[Path], run_id: int | None = None) -> RecordedRun:
    """The run ``run_id`` of ``files``, read in their order (default: the run with the most
    samples in them). A file of several that cannot be read at all (empty, not MCAP, not a
    regular file) is left out, ``state`` naming it; one file that cannot: InputError."""
    if not files:
        raise InputError("no recording to read")
    kept = _Kept()
    scans: list[RecordingScan] = []
    skipped: list[str] = []
    for path in files:
        scan = RecordingScan(path)
        try:
            kept.read(scan)
        except InputError as err:
            if len(files) == 1:
                raise
            skipped.append(f"{err}; left out")
            continue
        scans.append(scan)
    source = Path(files[0])
    if kept.undecodable:
        LOG.warning("%s: %d messages could not be decoded, left out", source, kept.undecodable)
    counts: dict[int, int] = {}
    for sample in kept.samples:
        counts[sample.run_id] = counts.get(sample.run_id, 0) + 1
    damage = "; ".join([scan.damage for scan in scans if scan.damage is not None] + skipped)
    run_id = _chosen_run(source, counts, run_id, damage or None)
    complete = not skipped and all(scan.complete for scan in scans)
    run = RecordedRun(
        source,
        run_id,
        [s for s in kept.samples if s.run_id == run_id],
        [e for e in kept.events if e.run_id == run_id],
        [d for d in kept.decisions if d.run_id == run_id],
        kept.metadata,
        complete,
        state="; ".join([scan.describe() for scan in scans] + skipped),
        runs_in_file=sorted(counts),
        stages=[d for d in kept.stages if d.run_id == run_id],
        result=next((r for r in reversed(kept.results) if r.run_id == run_id), None),
        sources=[Path(path) for path in files],
    )
    run.joint, run.motor_speed_rad_s, run.model_missing = _model_inputs(kept.metadata)
    run.controller = ControllerMarks.of(
        run.result, next((c for c in reversed(kept.controllers) if c.run_id == run_id), None)
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
