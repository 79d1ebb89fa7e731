"""The tool controller: conventional shutoff, hard limits, StopCommand, settling."""

from __future__ import annotations

import pytest

from services.rig.controller import RunController, StopSource
from services.rig.physics import TighteningPhysics
from shared.config import Program
from shared.contract import ToolRunState
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
