"""A multi-spindle cycle's common result from its spindles' results: OK only when every
spindle is; made when its last spindle's result comes, or, incomplete and NOK, when a run of
the next cycle starts first (an end lost in an outage)."""

from __future__ import annotations

from shared.contract import ToolState
from shared.quality import CycleTally, cycle_result
from tests.support import factories


def spindle_result(sync_id: int, spindle: int, verdict: str = "OK", part: str = "P1") -> object:
    return factories.result(
        sync_id + spindle - 1,
        spindle=spindle,
        sync_id=sync_id,
        part_id=part,
        result=verdict,
        nok_reasons="" if verdict == "OK" else "torque high: 241.0 Nm",
        time_ns=factories.T0 + spindle,
    )


def start(sync_id: int, spindle: int) -> ToolState:
    return ToolState(
        "st1", sync_id + spindle - 1, 7, 1, "running", 1, spindle=spindle, sync_id=sync_id
    )


def test_a_cycle_is_ok_only_when_every_spindle_is() -> None:
    results = {k: spindle_result(10, k) for k in (1, 2, 3)}
    ok = cycle_result("st1", 10, 3, results)  # type: ignore[arg-type]
    assert (ok.result, ok.nok_reasons, ok.part_id, ok.time_ns) == ("OK", "", "P1", factories.T0 + 3)
    assert [(s.spindle, s.run_id, s.result) for s in ok.spindles] == [
        (1, 10, "OK"), (2, 11, "OK"), (3, 12, "OK"),
    ]  # fmt: skip
    results[2] = spindle_result(10, 2, "NOK")
    nok = cycle_result("st1", 10, 3, results)  # type: ignore[arg-type]
    assert nok.result == "NOK" and nok.nok_reasons == "spindle 2 NOK (torque high: 241.0 Nm)"


def test_the_tally_gives_the_cycle_at_its_last_spindle_and_closes_one_left_incomplete() -> None:
    tally = CycleTally("st1", 3)
    assert [tally.on_start(start(10, k)) for k in (1, 2, 3)] == [[], [], []]
    assert tally.on_result(spindle_result(10, 2)) is None  # type: ignore[arg-type]
    assert tally.on_result(spindle_result(10, 1)) is None  # type: ignore[arg-type]
    done = tally.on_result(spindle_result(10, 3))  # type: ignore[arg-type]
    assert done is not None and done.result == "OK" and done.sync_id == 10
    # the next cycle: spindle 3's end never came; the cycle after starts
    for k in (1, 2, 3):
        tally.on_start(start(20, k))
    tally.on_result(spindle_result(20, 1))  # type: ignore[arg-type]
    tally.on_result(spindle_result(20, 2))  # type: ignore[arg-type]
    (left,) = tally.on_start(start(30, 1))
    assert (left.sync_id, left.result, left.nok_reasons) == (20, "NOK", "spindle 3 no result")
    assert [(s.spindle, s.run_id) for s in left.spindles] == [(1, 20), (2, 21), (3, None)]
    assert tally.on_start(start(30, 2)) == []  # the same cycle: nothing more to close
    # a single-spindle station's results make no cycle
    assert tally.on_result(factories.result(99)) is None
