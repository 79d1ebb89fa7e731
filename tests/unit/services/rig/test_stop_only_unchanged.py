"""A station whose tool only stops runs as before the final stage existed (golden runs).

Each row is one joint of the torque-only benchmark's families tightened by
the rig's tool controller (stop only: its program has no final stage) and
decided by the predictor core, the run halted one sample after the decision
as a StopCommand halts it: the deciding sample and reason, what stopped the
tool, the run's samples, the settled true torque and preload and the events.
The figures were taken at the commit before the final stage was added
(80582b9); the same code path must give them still, to the last digit.
"""

from __future__ import annotations

import math

import pytest

from services.rig.controller import RunController
from services.rig.physics import TighteningPhysics
from shared.stickslip import CoreDecision, PredictorCore, PredictorSettings
from tests.benchmarks.torque_only_joints import Joint, family_joints

#: (family, joint, torque-only, (decision sample, reason) or None, stop source, samples,
#: settled torque Nm, settled preload N, events)
GOLDEN: list[tuple[object, ...]] = [
    ("tune-a", 0, True, None, "shutoff_torque", 7771, 143.426195532, 41945.827278, 11),
    (
        "tune-a",
        0,
        False,
        (7491, "target_reached"),
        "shutoff_force",
        7517,
        139.86742173,
        40905.223483,
        11,
    ),
    ("tune-a", 1, True, None, "shutoff_torque", 2860, 48.231593982, 40972.023481, 76),
    (
        "tune-a",
        1,
        False,
        (2769, "target_reached"),
        "shutoff_force",
        2797,
        38.826432219,
        40972.023481,
        75,
    ),
    ("tune-a", 2, True, None, "shutoff_torque", 5534, 64.09140574, 44100.898398, 78),
    (
        "tune-a",
        2,
        False,
        (5329, "plateau_closest"),
        "stop_command",
        5360,
        52.528538844,
        43823.461915,
        77,
    ),
    (
        "tune-a",
        3,
        True,
        (824, "target_reached"),
        "shutoff_torque",
        852,
        263.122960032,
        60484.714688,
        4,
    ),
    (
        "tune-a",
        3,
        False,
        (761, "target_reached"),
        "shutoff_force",
        792,
        248.442028509,
        57112.276659,
        4,
    ),
    (
        "judge-b",
        0,
        True,
        (1331, "target_reached"),
        "stop_command",
        1362,
        217.357142566,
        57255.273948,
        15,
    ),
    (
        "judge-b",
        0,
        False,
        (1266, "target_reached"),
        "shutoff_force",
        1296,
        209.175589463,
        55101.383312,
        15,
    ),
    (
        "judge-b",
        1,
        True,
        (403, "target_reached"),
        "stop_command",
        434,
        98.682576529,
        44851.432279,
        29,
    ),
    (
        "judge-b",
        1,
        False,
        (379, "target_reached"),
        "shutoff_force",
        407,
        88.4520115,
        43568.330818,
        27,
    ),
    (
        "judge-b",
        2,
        True,
        (358, "target_reached"),
        "stop_command",
        389,
        139.865156994,
        47463.388101,
        0,
    ),
    (
        "judge-b",
        2,
        False,
        (347, "target_reached"),
        "shutoff_force",
        378,
        136.622425777,
        46364.767856,
        0,
    ),
    ("judge-b", 3, True, None, "shutoff_torque", 4727, 74.959806414, 47270.914886, 40),
    (
        "judge-b",
        3,
        False,
        (4480, "plateau_closest"),
        "stop_command",
        4511,
        54.346136591,
        47270.914886,
        40,
    ),
    (
        "paper",
        0,
        True,
        (1572, "target_reached"),
        "stop_command",
        1603,
        237.928495879,
        55742.460309,
        33,
    ),
    (
        "paper",
        0,
        False,
        (1445, "plateau_closest"),
        "stop_command",
        1476,
        202.632210879,
        54593.553784,
        32,
    ),
    (
        "paper",
        1,
        True,
        (1618, "target_reached"),
        "shutoff_torque",
        1648,
        127.221113702,
        63854.297407,
        12,
    ),
    (
        "paper",
        1,
        False,
        (1260, "target_reached"),
        "shutoff_force",
        1288,
        85.267509116,
        57091.501079,
        10,
    ),
    (
        "paper",
        2,
        True,
        (579, "target_reached"),
        "stop_command",
        610,
        169.901541576,
        41247.111889,
        32,
    ),
    (
        "paper",
        2,
        False,
        (533, "plateau_closest"),
        "stop_command",
        564,
        151.005810896,
        39692.175968,
        31,
    ),
    (
        "paper",
        3,
        True,
        (547, "target_reached"),
        "stop_command",
        578,
        90.667587258,
        42946.088501,
        10,
    ),
    (
        "paper",
        3,
        False,
        (470, "target_reached"),
        "shutoff_force",
        498,
        58.861123957,
        42945.594734,
        9,
    ),
]


def stop_only_run(joint: Joint, torque_only: bool) -> tuple[object, ...]:
    program = joint.program.model_copy(
        update={
            "target_torque_nm": joint.target_torque_nm if torque_only else None,
            "max_torque_nm": max(joint.program.max_torque_nm, 3 * joint.target_torque_nm),
        }
    )
    assert program.final_stage is None
    physics = TighteningPhysics(joint.constants, program, joint.rig, seed=joint.seed)
    controller = RunController(
        physics, program, run_id=1, settle_time_s=0.03, has_force_sensor=not torque_only
    )
    core = PredictorCore(
        PredictorSettings(
            target_force_n=None if torque_only else program.target_force_n,
            target_torque_nm=joint.target_torque_nm,
            has_force=not torque_only,
            motor_speed_rad_s=program.motor_speed_rad_s,
            constants=joint.constants,
        )
    )
    controller.start()
    decided: tuple[int, str] | None = None
    halt_at: int | None = None
    n = 0
    while not controller.finished and n < 60_000:
        m = controller.tick()
        n += 1
        if halt_at is not None and n >= halt_at:
            controller.request_stop(1)
            halt_at = None
        force = math.nan if torque_only else m.force_n
        for output in core.update(m.time_s, m.torque_nm, force, m.angle_deg):
            if isinstance(output, CoreDecision):
                decided, halt_at = (n, output.reason), n + 1
    return (
        decided,
        str(controller.stop_source),
        controller.samples,
        round(physics.true_torque_nm, 9),
        round(physics.true_force_n, 6),
        core.events,
    )


@pytest.mark.parametrize("row", GOLDEN, ids=lambda row: f"{row[0]}-{row[1]}-{row[2]}")
def test_a_stop_only_run_is_what_it_was_before_the_final_stage(row: tuple[object, ...]) -> None:
    family, number, torque_only, *golden = row
    assert isinstance(family, str) and isinstance(number, int) and isinstance(torque_only, bool)
    joint = family_joints(family, number + 1)[number]
    assert stop_only_run(joint, torque_only) == tuple(golden)
