"""Eq. 71 against the configured joint's analytical K1-K3 bands (core/model_bands.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from services.cli.main import main
from shared.config import RigSection
from shared.contract import write_trace
from shared.model import JointConstants, expected_constant_bands
from shared.stickslip import (
    MODEL_SLACK,
    CoreDecision,
    ModelBandCheck,
    PredictorCore,
    PredictorSettings,
)
from tests.support.model_band_runs import TRACE_JOINT, rig_decision
from tests.support.paths import JOINT_5_2
from tests.support.rig_fixtures import constants as paper_constants
from tests.support.rig_fixtures import paper_program, paper_rig
from tests.support.synthetic_runs import smooth_ramp, staircase

#: the same joint configured with a far lower μ_slip: slips ~8x larger, K1 ~8x lower
WRONG_JOINT = JointConstants(600.0, 80_000.0, 0.01, 0.36, 0.15)
PAPER_JOINT_FILE = JOINT_5_2


def stop_of(core: PredictorCore, trace_rows: list[tuple[float, float, float, float]]) -> object:
    for row in trace_rows:
        for output in core.update(*row):
            if isinstance(output, CoreDecision):
                return output
    return None


def settings(constants: JointConstants, torque_only: bool, **changes: object) -> PredictorSettings:
    values: dict[str, object] = {
        "target_force_n": None if torque_only else 40_000.0,
        "target_torque_nm": 40_000.0 * 0.01 * 0.36 if torque_only else None,
        "has_force": not torque_only,
        "motor_speed_rad_s": 0.5,
        "constants": constants,
    }
    values.update(changes)
    return PredictorSettings(**values)  # type: ignore[arg-type]


def test_the_staircase_is_far_outside_the_wrong_joints_band() -> None:
    bands = expected_constant_bands(WRONG_JOINT, 0.5)
    right = expected_constant_bands(TRACE_JOINT, 0.5)
    assert right.k1_max > 3 * MODEL_SLACK * bands.k1_max


@pytest.mark.parametrize("torque_only", [False, True])
def test_a_joint_outside_the_model_band_stops_with_constant_out_of_band(torque_only: bool) -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0, duration_s=2.0)
    core = PredictorCore(settings(WRONG_JOINT, torque_only))
    decision = stop_of(core, trace.rows())
    assert isinstance(decision, CoreDecision)
    assert decision.reason == "constant_out_of_band"
    assert "K1" in decision.detail
    # judged once the noise floor settled and n_K events carry the figure
    bands = core.model_bands
    assert bands is not None and bands.unsettled <= 3
    assert core.events == max(bands.unsettled, 1) + core.settings.constant_window


@pytest.mark.parametrize("torque_only", [False, True])
def test_the_right_joint_never_stops_on_its_band(torque_only: bool) -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0, duration_s=2.0)
    core = PredictorCore(settings(TRACE_JOINT, torque_only))
    decision = stop_of(core, trace.rows())
    assert isinstance(decision, CoreDecision)
    assert decision.reason in ("plateau_closest", "target_reached")
    assert core.model_bands is not None and core.model_bands.judged > 10
    assert max(core.model_bands.nearest_edge.values()) < 1.0


def test_a_joint_without_stick_slip_is_never_judged() -> None:
    core = PredictorCore(settings(WRONG_JOINT, False, target_force_n=1e9))
    assert stop_of(core, smooth_ramp().rows()) is None
    assert core.model_bands is not None and core.model_bands.judged == 0


def test_one_odd_event_does_not_move_the_median() -> None:
    check = ModelBandCheck(TRACE_JOINT, window_events=5)
    verdicts = []
    for j in range(12):
        period = 0.025 if j != 8 else 0.0025  # one wiggle taken for a slip
        # a drop of 7 Nm reloaded by the 7.5 Nm stick ramp of 25 ms: peaks rise 0.3 Nm
        verdicts.append(check.on_event(20.0 + j * 0.3, 7.0, period, 300.0, 0.5, 0.1))
    assert verdicts == [None] * 12
    assert check.judged > 0


# joints across the benchmark's ranges: (k_e, k_s, r, mu_stick, mu_slip, speed, target)
RIG_JOINTS = [
    (300.0, 60_000.0, 0.010, 0.15, 0.146, 0.15, 35_000.0),
    (1800.0, 150_000.0, 0.013, 0.35, 0.33, 1.5, 55_000.0),
    (900.0, 40_000.0, 0.009, 0.25, 0.23, 0.5, 45_000.0),
]


@pytest.mark.parametrize("torque_only", [False, True])
def test_the_rigs_normal_runs_never_stop_on_the_band(torque_only: bool) -> None:
    decision = rig_decision(paper_constants(), paper_program(), paper_rig(), torque_only, 7)
    assert decision is not None and decision.reason != "constant_out_of_band"
    for number, (k_e, k_s, r, mu_stick, mu_slip, speed, target) in enumerate(RIG_JOINTS):
        program = paper_program(
            target_force_n=target, motor_speed_rad_s=speed, start_force_n=0.25 * target
        )
        joint = JointConstants(k_e, k_s, r, mu_stick, mu_slip)
        decision = rig_decision(joint, program, RigSection(), torque_only, 2018 + number)
        assert decision is not None, (number, "no stop")
        assert decision.reason != "constant_out_of_band", (number, decision.detail)


def joint_file_with(tmp_path: Path, mu_slip: float) -> Path:
    text = PAPER_JOINT_FILE.read_text().replace("mu_slip = 0.35", f"mu_slip = {mu_slip}")
    path = tmp_path / f"joint-{mu_slip}.toml"
    path.write_text(text)
    return path


def test_predict_joint_feeds_the_model_band(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    paper = paper_constants()
    trace = staircase(
        k_e=paper.k_e_nm_per_rad,
        k_s=paper.k_s_n_per_rad,
        r=paper.r_m,
        mu_stick=paper.mu_stick,
        mu_slip=paper.mu_slip,
        torque_noise_nm=0.2,
        force_noise_n=30.0,
        duration_s=2.0,
    )
    path = tmp_path / "run.csv"
    write_trace(path, trace.csv_rows())
    reasons = {}
    for mu_slip in (0.35, 0.15):
        joint = joint_file_with(tmp_path, mu_slip)
        args = ["predict", str(path), "--target-force", "40000", "--joint", str(joint)]
        assert main(args) == 0
        records = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
        reasons[mu_slip] = [r["reason"] for r in records if r["type"] == "stop"]
    assert reasons[0.35] in (["plateau_closest"], ["target_reached"])
    assert reasons[0.15] == ["constant_out_of_band"]
