"""A final stage through the real processes over CAN: ``boltwatch up --program 3``.

The shipped program 3 tightens to 200 Nm in two stages. The rig plays a tool
controller that takes StageCommand (and says so in ToolStage); the station's
edge predictor switches it to the final speed, halts it on the target, gives
pulses back to the target (made likely here by asking for one whenever the
settled torque is 0.05 % short) and finishes each run. Every command is
recorded on ``boltwatch/st1/stage``, every stage the tool reports on
``boltwatch/st1/tool``, and lands in the run's summary and result. The same
program on a controller that only stops (``[rig] stage_commands = false``: no
ToolStage) runs stop-only: no StageCommand goes out, and the acquisition says
why.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

RUNS = 4
EAGER_PULSES = {"max_pulses = 2\n": "max_pulses = 2\npulse_below_pct = 0.05\n"}


def test_a_staged_program_switches_halts_pulses_and_finishes_every_run(tmp_path: Path) -> None:
    station = write_station(tmp_path, replacements=EAGER_PULSES)
    result = run_up(station, RUNS, "--program", "3")
    recorded = read_recordings(tmp_path / "recordings")
    summaries = recorded["boltwatch/st1/runs"]
    assert len(summaries) == RUNS, result.stdout
    stages = recorded["boltwatch/st1/stage"]
    states = recorded["boltwatch/st1/tool"]
    for summary in summaries:
        run_id = summary["run_id"]
        commands = [s for s in stages if s["run_id"] == run_id]
        said = [s["command"] for s in commands]
        assert summary["commands"] == "staged"
        assert said[0] == "final" and said[-1] == "finish", said
        assert summary["final_stage_s"] == pytest.approx(commands[0]["time_s"])
        pulses = [s["pulse"] for s in commands if s["command"] == "pulse"]
        assert summary["pulses"] == len(pulses) <= 2 and pulses == list(range(1, len(pulses) + 1))
        # each pulse ends in a halt: the station's StopCommand of that pulse, or the tool's
        # own shutoff at the target (a pulse of a few samples ends before the line decides)
        held = {s["pulses"] for s in states if s["run_id"] == run_id and s["stage"] == "holding"}
        assert set(pulses) <= held
        assert summary["stop_reason"] == "target_reached"
        assert abs(summary["reached_torque_nm"] - 200.0) < 2.0  # within the 196-204 window
    assert any(s["pulses"] for s in summaries), "no run took a pulse at a 0.05 % threshold"
    results = {r["run_id"]: r for r in recorded["boltwatch/st1/results"]}
    assert {r["pulses"] for r in results.values()} == {s["pulses"] for s in summaries}
    bus = recorded["boltwatch/st1/bus"][-1]
    assert bus["tool_commands"] == "staged" and bus["tool_commands_note"] == ""
    # every command but a pulse's halt (a StopCommand) went out as a StageCommand
    assert bus["stage_commands"] == sum(s["command"] != "stop" for s in stages)
    assert "in a final stage" in result.stdout


def test_a_controller_that_only_stops_gets_only_stops(tmp_path: Path) -> None:
    station = write_station(tmp_path, replacements={"[rig]\n": "[rig]\nstage_commands = false\n"})
    run_up(station, 2, "--program", "3")
    recorded = read_recordings(tmp_path / "recordings")
    assert "boltwatch/st1/stage" not in recorded
    summaries = recorded["boltwatch/st1/runs"]
    assert [s["commands"] for s in summaries] == ["stop", "stop"]
    assert all(s["final_stage_s"] is None and s["pulses"] == 0 for s in summaries)
    assert all(r["pulses"] is None for r in recorded["boltwatch/st1/results"])
    bus = recorded["boltwatch/st1/bus"][-1]
    assert bus["tool_commands"] == "stop" and bus["stage_commands"] == 0
    assert bus["tool_commands_note"] == "the tool controller sends no ToolStage"
