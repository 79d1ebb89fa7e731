"""The acquisition loop on a real python-can virtual bus."""

from __future__ import annotations

import dataclasses

import can

from services.acquisition.acquisition import Acquisition
from shared.contract import (
    Sample,
    StationDatabase,
    StopDecision,
    StopReason,
    ToolState,
    encode,
)
from tests.support.acquisition_bus import ListOutlet, drain, frame, status
from tests.support.paths import DBC_FILE

DATABASE = StationDatabase(DBC_FILE)
FRAME_IDS = {name: frame_id for frame_id, (name, _) in DATABASE.by_id.items()}


def decision(run_id: int) -> StopDecision:
    return StopDecision("st1", run_id, 0, 0.1, "plateau_closest", "", 100.0, 5e4, 5.1e4, 0)


def test_a_run_is_published_in_order_with_faults_counted(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", True, station, DATABASE, outlet)
    tool.send(status(42, 1))
    for counter in (0, 1, 2, 5, 6):  # 3 and 4 never sent: a gap
        tool.send(frame("ToolSensors", Torque=counter * 10.0, Angle=counter * 0.5, Counter=counter))
        tool.send(frame("JointSensors", Force=counter * 1000.0, Counter=counter))
    tool.send(can.Message(arbitration_id=0x555, data=b"\x01\x02", is_extended_id=False))
    tool.send(
        can.Message(arbitration_id=DATABASE.tool_sensors_id, data=b"\x00", is_extended_id=False)
    )
    tool.send(status(42, 2))
    drain(acquisition, station)

    assert [s.sequence for s in outlet.samples] == [0, 1, 2, 5, 6]
    assert {s.run_id for s in outlet.samples} == {42}
    assert [s.force_n for s in outlet.samples] == [0.0, 1000.0, 2000.0, 5000.0, 6000.0]
    assert all(s.time_ns > 0 for s in outlet.samples)
    assert [(s.run_id, s.state) for s in outlet.states] == [(42, "running"), (42, "done")]
    stats = acquisition.stats()
    assert (stats.samples, stats.counter_gaps, stats.missed_samples) == (5, 1, 2)
    assert (stats.unknown_ids, stats.wrong_length) == (1, 1)


def test_stop_command_only_for_the_running_run_and_only_once(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    tool, station = buses
    acquisition = Acquisition("st1", True, station, DATABASE, ListOutlet())
    assert not acquisition.send_stop(decision(7))  # no run yet
    tool.send(status(7, 1))
    drain(acquisition, station)
    assert not acquisition.send_stop(decision(8))  # another run
    assert acquisition.send_stop(decision(7))
    assert not acquisition.send_stop(decision(7))  # once per run
    assert acquisition.stats().late_decisions == 2  # the first two: no such run running
    received = tool.recv(1.0)
    assert received is not None and received.arbitration_id == DATABASE.stop_command_id
    signals = DATABASE.decode(received.arbitration_id, received.data)
    assert signals == {"RunId": 7, "Reason": int(StopReason.PLATEAU_CLOSEST)}
    assert tool.recv(0.05) is None
    assert acquisition.stats().stop_commands == 1


def test_an_advisory_decision_on_the_wire_stops_no_tool(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    """An advisory decision (``boltwatch import``, an Open Protocol bridge: decided after the
    fact) put on a station's ``decision`` key never becomes a StopCommand; it is counted."""
    tool, station = buses
    acquisition = Acquisition("st1", True, station, DATABASE, ListOutlet())
    tool.send(status(7, 1))
    drain(acquisition, station)
    advisory = dataclasses.replace(decision(7), advisory=True)
    assert not acquisition.decision(encode(advisory))
    assert tool.recv(0.05) is None
    stats = acquisition.stats()
    assert (stats.stop_commands, stats.bad_decisions) == (0, 1)
    assert acquisition.decision(encode(decision(7)))  # the run can still be stopped


def test_torque_only_station_publishes_without_force(buses: tuple[can.BusABC, can.BusABC]) -> None:
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", False, station, DATABASE, outlet)
    tool.send(status(1, 1))
    tool.send(frame("ToolSensors", Torque=1.5, Angle=3.0, Counter=0))
    drain(acquisition, station)
    assert [(s.sequence, s.force_n) for s in outlet.samples] == [(0, None)]


def test_a_run_id_starts_once_however_its_state_flips(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    """ToolStatus flipping every 5 ms for one run id gave 63 rows and 69 files."""
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", False, station, DATABASE, outlet)
    for _ in range(30):
        tool.send(status(42, 1))
        tool.send(status(42, 2))
    tool.send(status(43, 1))  # the next run starts as usual
    drain(acquisition, station)
    assert [(s.run_id, s.state) for s in outlet.states] == [
        (42, "running"),
        (42, "done"),
        (43, "running"),
    ]
    assert acquisition.stats().repeated_runs == 29


def test_the_done_state_says_whether_boltwatch_stopped_the_tool(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    """A run summary must say what actually stopped the tool."""
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition("st1", False, station, DATABASE, outlet)
    tool.send(status(42, 1))
    drain(acquisition, station)
    assert acquisition.send_stop(decision(42))
    tool.send(status(42, 2))
    tool.send(status(43, 1))  # this run the tool stops by itself; a decision comes late
    tool.send(status(43, 3))
    drain(acquisition, station)
    assert not acquisition.send_stop(decision(43))
    ends = [(s.run_id, s.state, s.stop_command) for s in outlet.states if s.state != "running"]
    assert ends == [(42, "done", "plateau_closest"), (43, "aborted", None)]
    assert acquisition.stats().late_decisions == 1


class RecordingDecider:
    """A Decider that decides at one sample, or fails at every one."""

    def __init__(self, decide_at: int | None = None, fail: bool = False) -> None:
        self.decide_at = decide_at
        self.fail = fail
        self.states: list[str] = []

    def on_tool_state(self, state: ToolState) -> None:
        self.states.append(state.state)

    def on_sample(self, sample: Sample) -> StopDecision | None:
        if self.fail:
            raise RuntimeError("a bug in the predictor")
        return decision(sample.run_id) if sample.sequence == self.decide_at else None


def play(tool: can.BusABC, samples: int) -> None:
    tool.send(status(42, 1))
    for counter in range(samples):
        tool.send(frame("ToolSensors", Torque=10.0, Angle=0.1 * counter, Counter=counter))


def test_an_edge_decision_goes_out_on_the_can_thread_at_its_sample(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    """The stop path of one sample: the decider's decision is a StopCommand
    within the call that handled its sample, before the sample is published."""
    tool, station = buses
    outlet = ListOutlet()
    decider = RecordingDecider(decide_at=3)
    acquisition = Acquisition("st1", False, station, DATABASE, outlet, decider=decider)
    play(tool, 6)
    drain(acquisition, station)
    assert decider.states == ["running"]
    assert acquisition.stats().stop_commands == 1
    stop = tool.recv(1.0)
    assert stop is not None and stop.arbitration_id == FRAME_IDS["StopCommand"]
    assert [s.time_s for s in outlet.samples] == [k / 1000.0 for k in range(6)]  # sample clock


def test_a_failing_predictor_never_stops_the_samples(
    buses: tuple[can.BusABC, can.BusABC],
) -> None:
    tool, station = buses
    outlet = ListOutlet()
    acquisition = Acquisition(
        "st1", False, station, DATABASE, outlet, decider=RecordingDecider(fail=True)
    )
    play(tool, 20)
    drain(acquisition, station)
    assert len(outlet.samples) == 20 and acquisition.stats().stop_commands == 0
