"""The simulated controller's pure parts: its result of a run, batch counting, alarms,
the result store's bound, curves that fit one 0900."""

from __future__ import annotations

import numpy as np
import pytest

from services.rig.controller import StopSource
from services.rig.openprotocol.controller_state import ControllerState
from services.rig.openprotocol.result_messages import coefficient_for, trace_curves
from services.rig.openprotocol.result_store import ResultStore
from services.rig.openprotocol.tightening import RunCurves, TighteningJudge
from shared.config import OpenProtocolSection, Program, RigOpenProtocolSection
from shared.openprotocol import Alarm, AlarmAcknowledgedOnController, encode
from tests.support.rig_fixtures import paper_program

SECTION = OpenProtocolSection(host="127.0.0.1")


def curves(
    peak_torque_nm: float, angle_deg: float, stop: StopSource, samples: int = 100
) -> RunCurves:
    torque = np.linspace(0.0, peak_torque_nm, samples)
    angle = np.linspace(0.0, angle_deg, samples)
    return RunCurves(torque, angle, np.zeros(samples), stop, slips=0)


def judge(**settings: object) -> TighteningJudge:
    return TighteningJudge("st1", 7, RigOpenProtocolSection.model_validate(settings), 500)


def test_the_result_judges_torque_and_angle_against_the_program_windows() -> None:
    program = paper_program()  # torque 180..240 Nm, angle 35..65 deg
    judged = judge()
    ok = judged.result(program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE), 10**18)
    low = judged.result(program, curves(150.0, 50.0, StopSource.SHUTOFF_FORCE), 10**18)
    high_angle = judged.result(program, curves(200.0, 80.0, StopSource.SHUTOFF_FORCE), 10**18)
    aborted = judged.result(program, curves(200.0, 50.0, StopSource.LIMIT_TIME), 10**18)
    assert (ok.ok, ok.torque_status, ok.angle_status) == (True, "ok", "ok")
    assert (ok.torque_min_nm, ok.torque_max_nm, ok.torque_target_nm) == (180.0, 240.0, 200.0)
    assert (low.ok, low.torque_status) == (False, "low")
    assert (high_angle.ok, high_angle.angle_status) == (False, "high")
    assert not aborted.ok and aborted.torque_status == "ok"  # aborted: NOK whatever the figures
    assert [t.tightening_id for t in (ok, low, high_angle, aborted)] == [500, 501, 502, 503]


def test_the_batch_counts_ok_tightenings_and_starts_again_when_complete() -> None:
    program = paper_program()
    judged = judge(batch_size=2)
    runs = [200.0, 150.0, 200.0, 200.0, 200.0]  # OK, NOK, OK, OK, OK
    results = [judged.result(program, curves(t, 50.0, StopSource.SHUTOFF_FORCE), 0) for t in runs]
    assert [(r.batch_counter, r.batch_status) for r in results] == [
        (1, "nok"),
        (1, "nok"),
        (2, "ok"),
        (1, "nok"),
        (2, "ok"),
    ]
    unbatched = judge(batch_size=0).result(
        program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE), 0
    )
    assert (unbatched.batch_counter, unbatched.batch_status) == (0, "not_used")


def test_an_alarm_is_raised_by_a_limit_and_cleared_by_the_next_good_run() -> None:
    program: Program = paper_program()
    state = ControllerState("st1", 7, program, SECTION, RigOpenProtocolSection())
    judged = judge()
    good = judged.result(program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE), 10**18)
    limit = judged.result(program, curves(330.0, 50.0, StopSource.LIMIT_TORQUE), 10**18)
    assert state.tightening(good) == []
    raised = state.tightening(limit)
    assert [type(m) for m in raised] == [Alarm] and raised[0].error_code == "E101"  # type: ignore[attr-defined]
    assert state.alarm_status(1).alarm_active
    cleared = state.tightening(good)
    assert cleared == [AlarmAcknowledgedOnController(error_code="E101")]
    assert not state.alarm_status(1).alarm_active
    assert (state.counters.tightenings, state.counters.ok, state.counters.nok) == (3, 2, 1)


def test_the_store_keeps_the_newest_and_serves_id_0_as_the_newest() -> None:
    program = paper_program()
    judged = judge()
    store = ResultStore(3)
    assert store.find(0) is None
    for _ in range(5):
        store.add(judged.result(program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE), 0))
    assert len(store) == 3 and store.forgotten == 2
    assert store.find(0) is store.find(504)
    assert store.find(501) is None and store.find(502) is not None
    with pytest.raises(ValueError, match="at least 1"):
        ResultStore(0)


@pytest.mark.parametrize(
    ("largest", "coefficient"),
    [(0.0, 0.001), (30.0, 0.001), (150.0, 0.005), (320.0, 0.01), (700.0, 0.05)],
)
def test_the_coefficient_holds_the_curve_in_16_bits(largest: float, coefficient: float) -> None:
    assert coefficient_for(np.array([0.0, -largest / 2, largest])) == coefficient


def test_a_run_longer_than_one_0900_holds_is_sent_every_kth_sample() -> None:
    program = paper_program()
    state = ControllerState("st1", 7, program, SECTION, RigOpenProtocolSection())
    long_run = judge().result(program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE, 6000), 0)
    short_run = judge().result(program, curves(200.0, 50.0, StopSource.SHUTOFF_FORCE, 1700), 0)
    (long_curve,) = trace_curves(long_run, (2,), state.identity)
    (short_curve,) = trace_curves(short_run, (2,), state.identity)
    assert (len(long_curve.samples), long_curve.time_step_s) == (3000, 0.002)
    assert (len(short_curve.samples), short_curve.time_step_s) == (1700, 0.001)
    assert len(encode(long_curve)) <= 10000  # fits the 4 digits of a length
