"""A multi-spindle controller's cycles in the bridge: a cycle's result (0101) that comes
before its spindles' tightenings waits for them, then names each spindle's run with the
controller's verdict; one whose spindle's tightening never comes goes after the wait without
that run; its status (0091) and its result make one cycle; a sync id made once is not made
again."""

from __future__ import annotations

import dataclasses

from services.openprotocol.controller_cycles import ControllerCycles
from shared.contract import CycleResult, TighteningResult
from shared.openprotocol import (
    MultiSpindleResult,
    MultiSpindleStatus,
    SpindleResult,
    SpindleStatus,
)
from tests.support import factories
from tests.support.openprotocol_examples import MULTI_SPINDLE_RESULT

WAIT_S = 5.0


class Clock:
    def __init__(self) -> None:
        self.now_s = 0.0

    def __call__(self) -> float:
        return self.now_s


def tightening(sync_id: int, spindle: int) -> TighteningResult:
    return factories.result(
        100 + spindle, spindle=spindle, sync_id=sync_id, part_id="VIN7", source="controller"
    )


def result_of(sync_id: int, verdicts: dict[int, bool]) -> MultiSpindleResult:
    spindles = tuple(SpindleResult(k, k, ok, 1, 200.0, True, 50) for k, ok in verdicts.items())
    return dataclasses.replace(
        MULTI_SPINDLE_RESULT,
        sync_tightening_id=sync_id,
        ok=all(verdicts.values()),
        spindles=spindles,
        vin="VIN7",
    )


def test_a_cycle_waits_for_its_spindles_tightenings_then_names_their_runs() -> None:
    published: list[object] = []
    clock = Clock()
    cycles = ControllerCycles("st1", published.append, WAIT_S, clock)
    cycles.on_tightening(tightening(7, 1))
    cycles.on_result(result_of(7, {1: True, 2: False}), factories.T0)
    status = MultiSpindleStatus(
        sync_tightening_id=7, time="2026-11-28:10:00:00", ok=False,
        spindles=(SpindleStatus(1, 1, True), SpindleStatus(2, 2, False)),
    )  # fmt: skip
    cycles.on_status(status, factories.T0)  # the same cycle's status: one cycle
    cycles.publish_ready()
    assert published == []  # spindle 2's tightening is still on its way (its curves)
    cycles.on_tightening(tightening(7, 2))
    cycles.publish_ready()
    (cycle,) = published
    assert isinstance(cycle, CycleResult)
    assert (cycle.sync_id, cycle.result, cycle.source, cycle.part_id) == (
        7,
        "NOK",
        "controller",
        "VIN7",
    )
    assert [(s.spindle, s.run_id, s.result) for s in cycle.spindles] == [
        (1, 101, "OK"),
        (2, 102, "NOK"),
    ]
    assert cycle.nok_reasons == "spindle 2 NOK"
    cycles.on_result(result_of(7, {1: True, 2: False}), factories.T0)  # sent again: made once
    cycles.publish_ready()
    assert len(published) == 1


def test_a_spindle_whose_tightening_never_comes_is_named_without_its_run_after_the_wait() -> None:
    published: list[object] = []
    clock = Clock()
    cycles = ControllerCycles("st1", published.append, WAIT_S, clock)
    cycles.on_tightening(tightening(8, 1))
    cycles.on_result(result_of(8, {1: True, 2: True}), factories.T0)
    clock.now_s = WAIT_S - 0.1
    cycles.publish_ready()
    assert published == []
    clock.now_s = WAIT_S
    cycles.publish_ready()
    (cycle,) = published
    assert isinstance(cycle, CycleResult) and cycle.result == "OK"  # the controller's verdict
    assert [(s.spindle, s.run_id) for s in cycle.spindles] == [(1, 101), (2, None)]
