"""What a run's summary says the station could command its tool: a final stage only when the
run's program has one and the tool takes it."""

from __future__ import annotations

import pytest

from services.predictor.served_station import ServedStation
from services.predictor.station_runs import StationRuns
from shared.contract import RunSummary, TighteningResult, ToolCommandsName, ToolState
from tests.support.factories import T0, S
from tests.support.rig_fixtures import station


@pytest.mark.parametrize(
    ("program_id", "tool_says", "commands", "pulses"),
    [
        (3, "staged", "staged", 0),  # program 3 has a final stage, the tool takes it
        (2, "staged", "stop", None),  # program 2 has none: stop only, whatever the tool takes
        (3, "stop", "stop", None),  # the tool takes no final stage
        (3, None, None, None),  # the tool did not say (a recording made before)
    ],
)
def test_a_runs_commands_are_those_of_its_program_and_its_tool(
    program_id: int,
    tool_says: ToolCommandsName | None,
    commands: ToolCommandsName | None,
    pulses: int | None,
) -> None:
    runs = StationRuns(ServedStation(station()))
    start = ToolState("st1", 7, 7, program_id, "running", T0, commands=tool_says)
    assert runs.on_tool(start) == []
    done = ToolState("st1", 7, 7, program_id, "done", T0 + S, commands=tool_says)
    result, summary = runs.on_tool(done)
    assert isinstance(result, TighteningResult) and isinstance(summary, RunSummary)
    assert (summary.commands, result.pulses) == (commands, pulses)
