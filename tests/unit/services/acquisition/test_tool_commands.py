"""What the station sends a tool that runs a final stage, on a real python-can virtual bus."""

from __future__ import annotations

import re
from pathlib import Path

import can

from services.acquisition.acquisition import Acquisition
from shared.contract import StageDecision, StationDatabase, StopDecision
from tests.support.acquisition_bus import ListOutlet, drain, frame, status
from tests.support.paths import DBC_FILE

DATABASE = StationDatabase(DBC_FILE)


def tool_stage(run_id: int, stage: int, pulses: int = 0, features: int = 1) -> can.Message:
    return frame("ToolStage", RunId=run_id, Stage=stage, Pulses=pulses, Features=features,
                 MaxPulses=2)  # fmt: skip


def stage(run_id: int, command: str, pulse: int = 0, reason: str = "near_target") -> StageDecision:
    return StageDecision("st1", run_id, 0, 0.5, command, reason, "", 190.0, pulse, 0)  # type: ignore[arg-type]


def stop(run_id: int) -> StopDecision:
    return StopDecision("st1", run_id, 0, 0.6, "target_reached", "", 200.0, None, None, 0)


def sent(tool: can.BusABC) -> list[tuple[str, dict[str, float | int]]]:
    out = []
    while (message := tool.recv(0.05)) is not None:
        name, _ = DATABASE.by_id[message.arbitration_id]
        out.append((name, DATABASE.decode(message.arbitration_id, message.data)))
    return out


def test_a_staged_tool_gets_its_stage_commands_and_a_stop_per_halt(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", False, station, DATABASE, outlet)
    tool.send(tool_stage(5, 0))  # before the run: what it takes
    tool.send(status(5, 1))
    drain(acquisition, station)
    assert (outlet.states[-1].commands, outlet.states[-1].stage) == ("staged", "rundown")
    assert acquisition.send(stage(5, "final"))
    assert acquisition.send(stop(5))
    tool.send(tool_stage(5, 3))  # holding
    drain(acquisition, station)
    assert (outlet.states[-1].state, outlet.states[-1].stage) == ("running", "holding")
    assert acquisition.send(stage(5, "pulse", 1, "lost_drop"))
    assert acquisition.send(stage(5, "stop", 1, "target_reached"))
    assert not acquisition.send(stage(5, "stop", 1, "target_reached"))  # that halt once
    assert not acquisition.send(stop(5))  # the run's first halt went out already
    assert acquisition.send(stage(5, "finish", 1, "settled"))
    assert not acquisition.send(stage(6, "finish", 1, "settled"))  # not the running run
    frames = sent(tool)
    assert [(name, signals.get("Command"), signals.get("Pulse")) for name, signals in frames] == [
        ("StageCommand", 1, 0),
        ("StopCommand", None, None),
        ("StageCommand", 2, 1),
        ("StopCommand", None, None),
        ("StageCommand", 3, 0),
    ]
    assert frames[2][1]["Reason"] == 3  # lost_drop
    stats = acquisition.stats()
    assert (stats.tool_commands, stats.stage_commands, stats.stop_commands) == ("staged", 3, 2)
    assert stats.late_decisions == 1 and stats.refused_stages == 0


def test_a_tool_that_sends_no_tool_stage_gets_only_stops(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", False, station, DATABASE, outlet)
    tool.send(status(5, 1))
    drain(acquisition, station)
    assert outlet.states[-1].commands == "stop" and outlet.states[-1].stage is None
    assert not acquisition.send(stage(5, "final"))
    assert acquisition.send(stop(5))
    assert [name for name, _ in sent(tool)] == ["StopCommand"]
    stats = acquisition.stats()
    assert (stats.tool_commands, stats.refused_stages) == ("stop", 1)
    assert stats.tool_commands_note == "the tool controller sends no ToolStage"
    tool.send(tool_stage(5, 0, features=0))  # it sends one, but takes no StageCommand
    drain(acquisition, station)
    note = acquisition.stats().tool_commands_note
    assert note == "the tool controller says it takes no StageCommand"


def test_a_station_file_or_a_dbc_without_stages_runs_stop_only(
    buses: tuple[can.BusABC, can.BusABC], tmp_path: Path
) -> None:
    tool, station = buses
    by_file = Acquisition("st1", False, station, DATABASE, ListOutlet(), stage_commands=False)
    tool.send(tool_stage(5, 0))
    drain(by_file, station)
    assert by_file.stats().tool_commands_note == (
        "the station file says can.tool_commands = 'stop'"
    )
    older = tmp_path / "older.dbc"
    text = DBC_FILE.read_text()
    text = re.sub(r"BO_ 17 StageCommand.*?\n\n", "", text, flags=re.DOTALL)
    text = re.sub(r"BO_ 129 ToolStage.*?\n\n", "", text, flags=re.DOTALL)
    text = "\n".join(
        line for line in text.splitlines() if " 17 " not in line and " 129 " not in line
    )
    older.write_text(text)
    database = StationDatabase(older)
    assert not database.has_stages and database.stage_command_id is None
    by_dbc = Acquisition("st1", False, station, database, ListOutlet())
    tool.send(tool_stage(5, 0))  # an unknown id to this DBC: counted, not understood
    drain(by_dbc, station)
    stats = by_dbc.stats()
    assert stats.tool_commands_note == "older.dbc has no StageCommand" and stats.unknown_ids == 1
