"""The tool controller: conventional shutoff, hard limits, StopCommand, settling, a final stage."""

from __future__ import annotations

import pytest

from services.rig.controller import FINAL_SHUTOFF_SAMPLES, RunController, StopSource
from services.rig.physics import TighteningPhysics
from shared.config import FinalStage, Program
from shared.contract import StageCommandCode, ToolRunState, ToolStageCode
from tests.support.rig_fixtures import constants, paper_program, paper_rig

SETTLE_S = 0.03


def controller(
    program: Program, *, has_force_sensor: bool = True, shutoff: bool = True
) -> RunController:
    physics = TighteningPhysics(constants(), program, paper_rig(), seed=8)
    run = RunController(
        physics,
        program,
        run_id=42,
        settle_time_s=SETTLE_S,
        has_force_sensor=has_force_sensor,
        shutoff=shutoff,
    )
    run.start()
    return run


def run_to_end(run: RunController, max_samples: int = 10_000) -> None:
    for _ in range(max_samples):
        run.tick()
        if run.finished:
            return
    raise AssertionError("run did not finish")


def test_conventional_force_shutoff_then_settles() -> None:
    program = paper_program(target_force_n=30_000.0)
    run = controller(program)
    forces = []
    while not run.finished:
        forces.append(run.tick().force_n)
    assert run.state is ToolRunState.DONE
    assert run.stop_source is StopSource.SHUTOFF_FORCE
    assert run.halt_time_s is not None
    halt_index = round(run.halt_time_s * 1000) - 1
    assert forces[halt_index] >= 30_000.0
    assert max(forces[:halt_index]) < 30_000.0  # stopped when first reached
    assert run.samples - halt_index - 1 >= round(SETTLE_S * 1000)
    assert run.physics.settled


def test_torque_shutoff_without_force_sensor() -> None:
    program = paper_program(target_torque_nm=120.0)
    run = controller(program, has_force_sensor=False)
    run_to_end(run)
    assert run.stop_source is StopSource.SHUTOFF_TORQUE
    assert run.state is ToolRunState.DONE
    assert run.physics.true_force_n < 40_000.0  # the 56 kN force target is ignored


def test_torque_shutoff_when_program_has_no_force_target() -> None:
    run = controller(paper_program(target_force_n=None, target_torque_nm=100.0))
    run_to_end(run)
    assert run.stop_source is StopSource.SHUTOFF_TORQUE


@pytest.mark.parametrize(
    ("changes", "source"),
    [
        ({"max_torque_nm": 90.0}, StopSource.LIMIT_TORQUE),
        ({"max_force_n": 25_000.0}, StopSource.LIMIT_FORCE),
        ({"max_angle_deg": 10.0}, StopSource.LIMIT_ANGLE),
        ({"max_time_s": 0.2}, StopSource.LIMIT_TIME),
    ],
)
def test_hard_limits_abort(changes: dict[str, float], source: StopSource) -> None:
    run = controller(paper_program(**changes))
    run_to_end(run)
    assert run.state is ToolRunState.ABORTED
    assert run.stop_source is source


def test_without_shutoff_runs_past_target_to_a_limit() -> None:
    program = paper_program()
    run = controller(program, shutoff=False)
    run_to_end(run)
    assert run.state is ToolRunState.ABORTED
    assert run.stop_source is StopSource.LIMIT_FORCE
    assert run.physics.true_force_n > 56_000.0  # past the target


def test_stop_command_for_this_run_only() -> None:
    run = controller(paper_program())
    for _ in range(100):
        run.tick()
    assert not run.request_stop(41)
    assert run.physics.motor_running
    assert run.request_stop(42)
    assert not run.physics.motor_running
    assert not run.request_stop(42)  # already stopping
    run_to_end(run)
    assert run.state is ToolRunState.DONE
    assert run.stop_source is StopSource.STOP_COMMAND
    assert run.physics.true_force_n < 30_000.0


def test_tick_needs_a_started_run() -> None:
    program = paper_program()
    physics = TighteningPhysics(constants(), program, paper_rig(), seed=1)
    run = RunController(physics, program, run_id=1, settle_time_s=SETTLE_S)
    with pytest.raises(RuntimeError, match="not running"):
        run.tick()
    assert not run.request_stop(1)


# -- a final stage ------------------------------------------------------------------------


def staged_controller(accepts_stages: bool = True, **stage: object) -> RunController:
    program = paper_program(
        target_force_n=None,
        target_torque_nm=200.0,
        final_stage=FinalStage.model_validate({"speed_rad_s": 0.05, **stage}),
    )
    physics = TighteningPhysics(constants(), program, paper_rig(), seed=8)
    run = RunController(
        physics,
        program,
        run_id=42,
        settle_time_s=SETTLE_S,
        has_force_sensor=False,
        accepts_stages=accepts_stages,
    )
    run.start()
    return run


def ticks_until(run: RunController, torque_nm: float) -> None:
    for _ in range(20_000):
        if run.tick().torque_nm >= torque_nm:
            return
    raise AssertionError(f"torque never reached {torque_nm} Nm")


def test_a_staged_run_turns_slower_holds_after_the_halt_pulses_and_finishes() -> None:
    run = staged_controller()
    ticks_until(run, 180.0)
    assert run.request_stage(42, StageCommandCode.FINAL)
    assert run.stage is ToolStageCode.FINAL and run.physics.motor_speed_rad_s == 0.05
    assert not run.request_stage(42, StageCommandCode.PULSE)  # no pulse while it turns
    assert run.request_stop(42)
    for _ in range(100):  # it holds the run open well past its settle time
        run.tick()
    assert run.stage is ToolStageCode.HOLDING and run.state is ToolRunState.RUNNING
    assert run.request_stage(42, StageCommandCode.PULSE)
    assert (run.stage, run.pulses, run.physics.motor_speed_rad_s) == (
        ToolStageCode.PULSE,
        1,
        0.05,
    )
    run.tick()
    assert run.request_stop(42)  # the pulse's own halt
    run.tick()
    assert run.stage is ToolStageCode.HOLDING
    assert not run.request_stage(41, StageCommandCode.FINISH)  # another run's
    assert run.request_stage(42, StageCommandCode.FINISH)
    run_to_end(run)
    assert run.state is ToolRunState.DONE and run.stop_source is StopSource.STOP_COMMAND


def test_pulses_stop_at_max_pulses_and_an_unattended_hold_ends_by_itself() -> None:
    run = staged_controller(max_pulses=1, hold_s=0.3)
    ticks_until(run, 180.0)
    run.request_stage(42, StageCommandCode.FINAL)
    run.request_stop(42)
    run.tick()
    assert run.request_stage(42, StageCommandCode.PULSE)
    run.tick()
    run.request_stop(42)
    run.tick()
    assert not run.request_stage(42, StageCommandCode.PULSE)  # no pulse left
    held = 0
    while not run.finished:  # nobody finishes it: it ends hold_s after the halt
        run.tick()
        held += 1
    assert run.state is ToolRunState.DONE and 299 <= held <= 360


def test_back_to_the_rundown_speed_and_its_own_switch_at_a_torque() -> None:
    run = staged_controller()
    ticks_until(run, 150.0)
    run.request_stage(42, StageCommandCode.FINAL)
    assert run.request_stage(42, StageCommandCode.RUNDOWN)
    assert run.stage is ToolStageCode.RUNDOWN and run.physics.motor_speed_rad_s == 0.5
    by_itself = staged_controller(switch="torque", switch_torque_nm=190.0)
    ticks_until(by_itself, 190.0)
    assert by_itself.stage is ToolStageCode.FINAL
    assert by_itself.physics.motor_speed_rad_s == 0.05


def test_its_own_shutoff_in_the_final_stage_watches_the_filtered_torque() -> None:
    run = staged_controller()
    ticks_until(run, 195.0)
    run.request_stage(42, StageCommandCode.FINAL)
    torques = []
    while run.physics.motor_running:
        torques.append(run.tick().torque_nm)
    assert run.stop_source is StopSource.SHUTOFF_TORQUE and run.stage is ToolStageCode.HOLDING
    assert sum(torques[-FINAL_SHUTOFF_SAMPLES:]) / FINAL_SHUTOFF_SAMPLES >= 200.0


def test_a_controller_that_only_stops_ignores_stage_commands() -> None:
    run = staged_controller(accepts_stages=False)
    assert not run.staged
    ticks_until(run, 180.0)
    assert not run.request_stage(42, StageCommandCode.FINAL)
    assert run.physics.motor_speed_rad_s == 0.5
    run.request_stop(42)
    run_to_end(run)  # ends after its settle time, as every stop-only run
    assert run.state is ToolRunState.DONE and run.pulses == 0
