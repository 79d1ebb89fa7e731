"""One joint tightened by a tool that runs a final stage, offline: the code the station runs.

The rig's own tool controller (``services.rig.controller.RunController``: the
final stage's speed, the hold, the pulses, its filtered shutoff at the target
and its hard limits) on the rig's physics, and the predictor's pure core with
the program's final stage, as a staged station decides. Every command the
core gives (final, rundown, stop, pulse, finish) reaches the controller
``latency_samples`` after the sample that decided it (1: as a StopCommand does
in the stop-only benchmark, ``bench_torque_only.run``; 0: as the live rig
obeys one, within the period of the deciding sample). The tool's own halts are
told to the core as the acquisition tells them (``ToolStage`` holding).

Used by ``tests/benchmarks/bench_torque_only.py`` and the tests of the final stage.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from services.rig.controller import RunController
from services.rig.physics import TighteningPhysics
from shared.config import FinalStage, Program, RigSection
from shared.contract import StageCommandCode, ToolStageCode
from shared.model import JointConstants
from shared.stickslip import CoreCommand, CoreDecision, PredictorCore, PredictorSettings

#: the controller's settle time after a halt (the rig's default): a stop-only run ends then
SETTLE_TIME_S = 0.03
COMMANDS = {
    "final": StageCommandCode.FINAL,
    "rundown": StageCommandCode.RUNDOWN,
    "pulse": StageCommandCode.PULSE,
    "finish": StageCommandCode.FINISH,
}


@dataclass(frozen=True)
class StagedEnd:
    """Where a staged run left the joint, and what it took."""

    torque_nm: float  # settled, true
    force_n: float
    reason: str  # the first halt's reason (the core's), or what stopped the tool
    detail: str
    cycle_samples: int  # start to the run's end (the controller's DONE)
    pulses: int
    switched: bool  # the final stage ran
    commands: tuple[str, ...]  # every command the core gave, in order ("final", "pulse 1", ...)
    said: tuple[CoreDecision | CoreCommand, ...] = ()  # the same, as the core gave them


def staged_program(
    program: Program,
    final_share: float,
    target_torque_nm: float | None,
    target_force_n: float | None,
    max_pulses: int = 2,
) -> Program:
    """``program`` with a final stage at ``final_share`` of its speed and the given target."""
    stage = FinalStage(speed_rad_s=final_share * program.motor_speed_rad_s, max_pulses=max_pulses)
    return program.model_copy(
        update={
            "final_stage": stage,
            "target_torque_nm": target_torque_nm,
            "target_force_n": target_force_n,
            "max_torque_nm": max(program.max_torque_nm, 3.0 * (target_torque_nm or 0.0)),
        }
    )


def run_staged(
    constants: JointConstants,
    program: Program,
    rig: RigSection,
    seed: int,
    torque_only: bool,
    latency_samples: int = 1,
    max_samples: int | None = None,
    reaction_samples: float | None = None,
) -> StagedEnd:
    """Tighten one joint with ``program`` (it has a final stage) to the controller's end.

    ``latency_samples``: samples the tool still runs after the deciding sample before a
    command takes effect; ``reaction_samples``: what the core assumes of it (default: the
    same; a station's default is 1, while the live rig obeys within the deciding sample's
    period: ``bench_live_accuracy.py`` compares with latency 0, reaction 1)."""
    assert program.final_stage is not None
    physics = TighteningPhysics(constants, program, rig, seed=seed)
    controller = RunController(
        physics, program, run_id=1, settle_time_s=SETTLE_TIME_S, has_force_sensor=not torque_only
    )
    core = PredictorCore(
        PredictorSettings(
            target_force_n=None if torque_only else program.target_force_n,
            target_torque_nm=program.target_torque_nm,
            has_force=not torque_only,
            motor_speed_rad_s=program.motor_speed_rad_s,
            constants=constants,
            reaction_samples=float(
                latency_samples if reaction_samples is None else reaction_samples
            ),
            final_stage=program.final_stage,
        )
    )
    limit = max_samples if max_samples is not None else int(program.max_time_s * 1000) + 1000
    due: deque[tuple[int, CoreDecision | CoreCommand]] = deque()
    given: list[str] = []
    outputs: list[tuple[int, CoreDecision | CoreCommand]] = []
    told_halted = False
    reason, detail = "", ""
    controller.start()
    for n in range(limit):
        # a command decided at sample k takes effect before sample k + latency + 1
        while due and due[0][0] < n:
            _apply(controller, due.popleft()[1])
        if controller.finished:
            break
        m = controller.tick()
        if controller.stage is ToolStageCode.HOLDING and not told_halted:
            told_halted = True
            if core.decision is None:
                core.on_tool_halted()
        elif controller.stage is not ToolStageCode.HOLDING:
            told_halted = False
        force = math.nan if torque_only else m.force_n
        for output in core.update(m.time_s, m.torque_nm, force, m.angle_deg):
            if isinstance(output, CoreDecision):
                reason, detail = output.reason, output.detail
                given.append("stop")
            elif isinstance(output, CoreCommand):
                given.append(
                    output.command + (f" {output.pulse}" if output.command == "pulse" else "")
                )
            else:
                continue
            due.append((n + latency_samples, output))
            outputs.append((n, output))
    final = core.final_stage
    return StagedEnd(
        torque_nm=physics.true_torque_nm,
        force_n=physics.true_force_n,
        reason=reason or str(controller.stop_source),
        detail=detail,
        cycle_samples=controller.samples,
        pulses=controller.pulses,
        switched=final is not None and final.switched_at_s is not None,
        commands=tuple(given),
        said=tuple(output for _, output in outputs),
    )


def _apply(controller: RunController, output: CoreDecision | CoreCommand) -> None:
    """What the acquisition sends the tool for ``output``: a StopCommand or a StageCommand."""
    if isinstance(output, CoreDecision) or output.command == "stop":
        controller.request_stop(controller.run_id)
    else:
        controller.request_stage(controller.run_id, COMMANDS[output.command])
