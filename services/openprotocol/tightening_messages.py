"""One tightening as the messages a CAN station publishes for a run, in the same order.

The predictor, the recorder, the wear ledger, ``up`` and ``status`` work
unchanged on a bridge's station because it publishes what an acquisition and
its predictor would, in their order (the order ``boltwatch import`` records
too):

1. ``tool``: :class:`ToolState` running, at the first sample's time;
2. ``samples``: one :class:`Sample` per trace sample at the controller's own
   timing (``time_ns`` = the trace's time stamp + i * its time step; ``time_s``
   = i * time step), torque and angle paired by index (an angle curve that is
   shorter or missing leaves NaN, never a shifted angle); no preload
   (``force_n`` None). The station's queued publisher sends them in
   ``SampleBatch``es;
3. after the sample that caused each, the predictor's after-the-fact outputs
   (:func:`shared.stickslip.advisory_replay.replay_run`: events, intensities,
   the decision marked advisory);
4. ``tool``: :class:`ToolState` done, 1 ns after the last sample (without
   samples: at the result's time stamp); ``stop_command`` None: the controller
   stopped its tool;
5. ``controller``: the controller's own result (:class:`ControllerResult`, one
   step made of its torque and angle limits, targets and finals);
6. ``results``: the :class:`TighteningResult` made from it
   (:func:`shared.quality.controller_result.controller_result`, source
   ``controller``), its figures judged against ``windows`` where the caller
   gives one (the station's pset, else the controller's pset as its last 0061
   said: :mod:`.tightening_flow`), else against the result's own limits;
7. ``runs``: the replay's :class:`RunSummary` (stop reason None).

A multi-spindle system's tightening (:attr:`ResultFigures.sync_id`) names its
spindle and sync id in its states, result and summary.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from services.openprotocol.controller_tightening import ResultFigures, Tightening
from shared.contract import ControllerFunction, ControllerResult, ControllerStep, Sample, ToolState
from shared.quality import Window, controller_result
from shared.stickslip import StoppedRun, replay_run

#: the name of the one step a bridge's ControllerResult has (Open Protocol gives no steps)
STEP_NAME = "Tightening"


def stopped_run(
    station: str, tool_id: int, run_id: int, tightening: Tightening
) -> tuple[StoppedRun, list[Sample]]:
    """The run as the predictor's replay takes it, and its samples."""
    result = tightening.result
    torque, angle = tightening.torque, tightening.angle
    base = torque if torque is not None else angle
    samples: list[Sample] = []
    if base is not None:
        count = len(base.values)
        torques = torque.values if torque is not None else ()
        angles = angle.values if angle is not None else ()
        for index in range(count):
            samples.append(
                Sample(
                    station,
                    run_id,
                    index,
                    base.time_ns(index),
                    torques[index] if index < len(torques) else math.nan,
                    angles[index] if index < len(angles) else math.nan,
                    None,
                    index * base.time_step_s,
                )
            )
    started_ns = samples[0].time_ns if samples else result.time_ns
    ended_ns = samples[-1].time_ns + 1 if samples else result.time_ns
    run = StoppedRun(
        station=station,
        run_id=run_id,
        tool_id=tool_id,
        program_id=result.program_id,
        started_ns=started_ns,
        ended_ns=ended_ns,
        times_ns=[sample.time_ns for sample in samples],
        run_time_s=[sample.time_s or 0.0 for sample in samples],
        torque_nm=[sample.torque_nm for sample in samples],
        angle_deg=[sample.angle_deg for sample in samples],
        target_torque_nm=result.torque_target_nm,
        reached_torque_nm=result.torque_nm,
        reached_angle_deg=result.angle_deg,
    )
    return run, samples


def tightening_messages(
    station: str,
    tool_id: int,
    run_id: int,
    tightening: Tightening,
    program_name: str = "",
    windows: Mapping[str, Window] | None = None,
) -> list[Any]:
    """Every message of the tightening, in the order a CAN station publishes them;
    ``windows``: "torque" / "angle" -> the window its figure is judged against."""
    run, samples = stopped_run(station, tool_id, run_id, tightening)
    replayed = replay_run(run)
    result = tightening.result
    spindle, sync_id = result.spindle, result.sync_id
    messages: list[Any] = [
        ToolState(
            station,
            run_id,
            tool_id,
            result.program_id,
            "running",
            run.started_ns,
            spindle=spindle,
            sync_id=sync_id,
        )
    ]
    outputs = replayed.outputs
    next_output = 0
    for index, sample in enumerate(samples):
        messages.append(sample)
        while next_output < len(outputs) and outputs[next_output][0] <= index:
            messages.append(outputs[next_output][2])
            next_output += 1
    messages += [message for _, _, message in outputs[next_output:]]
    messages.append(
        ToolState(
            station,
            run_id,
            tool_id,
            result.program_id,
            "done",
            run.ended_ns,
            spindle=spindle,
            sync_id=sync_id,
        )
    )
    controller = controller_message(station, tool_id, run_id, result, run.ended_ns, len(samples))
    messages.append(controller)
    judged = controller_result(
        controller,
        replayed.summary,
        program_name,
        "controller",
        result.tightening_id,
        windows,
    )
    messages.append(dataclasses.replace(judged, spindle=spindle, sync_id=sync_id))
    messages.append(dataclasses.replace(replayed.summary, spindle=spindle, sync_id=sync_id))
    return messages


def controller_message(
    station: str, tool_id: int, run_id: int, result: ResultFigures, time_ns: int, samples: int
) -> ControllerResult:
    """The controller's own result: its verdict, part, batch, and one step of its figures.

    The step's functions, named as :mod:`shared.quality.controller_result` reads
    them: ``TF Torque`` (target, final torque) or, on an angle strategy without
    a torque target, ``TF Angle``; ``MF TorqueMin`` / ``MF TorqueMax`` /
    ``MF AngleMin`` / ``MF AngleMax`` (the limits, each with the final value)
    where the controller gave a window; ``Torque`` / ``Angle`` (no nominal)
    for a final value no function above carries (a result fetched by id: 0065
    gives no targets or limits). The batch: its counter as ``batch_ok``,
    its size as ``batch_max_ok`` (a batch is done when that many are OK).
    """
    verdict = "OK" if result.ok else "NOK"
    functions: list[ControllerFunction] = []
    if result.torque_target_nm is not None:
        functions.append(ControllerFunction("TF Torque", result.torque_target_nm, result.torque_nm))
    elif result.angle_target_deg is not None:
        functions.append(ControllerFunction("TF Angle", result.angle_target_deg, result.angle_deg))
    for name, limit, value in (
        ("MF TorqueMin", result.torque_min_nm, result.torque_nm),
        ("MF TorqueMax", result.torque_max_nm, result.torque_nm),
        ("MF AngleMin", result.angle_min_deg, result.angle_deg),
        ("MF AngleMax", result.angle_max_deg, result.angle_deg),
    ):
        if limit is not None:
            functions.append(ControllerFunction(name, limit, value))
    for quantity, value in (("Torque", result.torque_nm), ("Angle", result.angle_deg)):
        if not any(function.name.split()[-1].startswith(quantity) for function in functions):
            functions.append(ControllerFunction(quantity, None, value))  # a final value alone
    step = ControllerStep(
        name=result.strategy or STEP_NAME,
        result=verdict,
        quality_code="",
        samples=samples,
        functions=functions,
    )
    return ControllerResult(
        station=station,
        run_id=run_id,
        tool_id=tool_id,
        program_id=result.program_id,
        time_ns=time_ns,
        result=verdict,
        quality_code="",
        part_id=result.part_id,
        torque_unit="Nm",
        torsion_release_samples=None,
        batch_number=None,
        batch_ok=result.batch_counter,
        batch_nok=None,
        batch_max_ok=result.batch_size,
        batch_max_nok=None,
        batch_canceled=None,
        batch_direction_ok=None,
        batch_direction_nok=None,
        steps=[step],
    )
