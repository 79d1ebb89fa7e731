"""An alert's condition state as a SCADA moves it (pure): raised, raised again while on,
acknowledged, confirmed, off, raised anew; what Acknowledge and Confirm refuse."""

from __future__ import annotations

import pytest

from services.opcua.condition_states import ConditionMethodError, ConditionState, Said

ON = Said(1, "tool 7 is due", 500, 1, (1033, "ThresholdViolationConditionClassType"))
OFF = Said(2, "tool 7 serviced", 100, 1, (1036, "ThresholdViolationResolvedConditionClassType"))


def _states(state: ConditionState) -> tuple[bool, bool, bool, bool]:
    return state.active, state.acked, state.confirmed, state.retain


def test_a_condition_is_retained_until_it_is_off_acknowledged_and_confirmed() -> None:
    state = ConditionState("wear/7", "wear", "Wear of tool 7")
    assert _states(state) == (False, True, True, False)
    state.raised(ON)
    state.notified(b"first")
    assert _states(state) == (True, False, True, True)
    state.raised(ON._replace(time_ns=3, message="tool 7 is due (2 runs)"))  # again, while on
    state.notified(b"second")
    assert _states(state) == (True, False, True, True)
    state.act("acknowledged", b"first", "seen", "scada")  # the notification it saw
    assert _states(state) == (True, True, False, True)
    assert (state.comment, state.client_user) == ("seen", "scada")
    state.act("confirmed", b"second", "done", "scada")
    assert _states(state) == (True, True, True, True)  # on: still retained
    assert state.cleared(OFF)
    assert _states(state) == (False, True, True, False)
    assert (state.severity, state.last_severity) == (100, 500)
    assert not state.cleared(OFF)  # off already: nothing to report
    state.raised(ON)  # a new occurrence: to acknowledge again, old notifications no more
    assert _states(state) == (True, False, True, True)
    with pytest.raises(ConditionMethodError, match="BadEventIdUnknown"):
        state.act("acknowledged", b"first", "", "scada")


@pytest.mark.parametrize(
    ("steps", "refused"),
    [
        ([("acknowledged", b"unknown")], "BadEventIdUnknown"),
        ([("acknowledged", b"id"), ("acknowledged", b"id")], "BadConditionBranchAlreadyAcked"),
        ([("confirmed", b"id")], "BadConditionBranchAlreadyConfirmed"),  # nothing to confirm yet
        (
            [("acknowledged", b"id"), ("confirmed", b"id"), ("confirmed", b"id")],
            "BadConditionBranchAlreadyConfirmed",
        ),
    ],
    ids=["unknown EventId", "acknowledged twice", "confirmed unacknowledged", "confirmed twice"],
)
def test_what_acknowledge_and_confirm_refuse(steps: list[tuple[str, bytes]], refused: str) -> None:
    state = ConditionState("alarm/E404", "alarm", "Controller alarm E404")
    state.raised(ON)
    state.notified(b"id")
    *done, (action, event_id) = steps
    for step, known in done:
        state.act(step, known, "", "scada")  # type: ignore[arg-type]
    before = _states(state)
    with pytest.raises(ConditionMethodError) as raised:
        state.act(action, event_id, "", "scada")  # type: ignore[arg-type]
    assert raised.value.status == refused
    assert _states(state) == before  # a refusal changes nothing
    state.act("commented", b"id", "a comment", "hmi")  # a comment, any time
    assert (state.comment, state.client_user) == ("a comment", "hmi")
