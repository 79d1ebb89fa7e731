"""Each live service built in-process on a real zenoh session, ready to be fuzzed.

A target is a context manager with the channels it subscribes to (zenoh
keys below ``boltwatch/<station>/``), ``send(channel, payload)`` from a
second session on loopback (BLOCK: nothing is dropped on the way), the
number of payloads it has refused (``refused()``), whether it is alive, and
``prove_serving()``: a good message after the bad ones is handled as usual
(raises AssertionError when not).

- :class:`AcquisitionTarget`: :class:`Acquisition` on a python-can
  ``virtual`` bus, its decision subscriber (``decision_handler``); a good
  decision must become a ``StopCommand`` frame on the bus;
- :class:`PredictorTarget`: :class:`PredictorService` for station pt1 (its
  samples, tool states and part scans); a good run must be decided;
- :class:`RecorderTarget`: :class:`RecorderService` (``RunningRecorder``)
  writing MCAP into a folder; a good run must be read back from its file,
  and every refused payload from the raw channels, byte for byte.
"""

from __future__ import annotations

import itertools
import json
import threading
import time
from dataclasses import replace
from pathlib import Path
from types import TracebackType
from typing import Any

import can
import zenoh
from mcap.reader import make_reader

from services.acquisition.acquisition import Acquisition
from services.acquisition.service import decision_handler
from services.predictor.service import PredictorService
from shared.config import load_line, load_station
from shared.contract import (
    CHANNELS,
    BusStats,
    Sample,
    StationDatabase,
    StopDecision,
    ToolState,
    channels,
    decode,
    encode,
    keys,
)
from shared.recordings.mcap import RAW_ENCODING
from shared.runtime import ServiceSkeleton, zenoh_config
from tests.support.fuzz.payloads import template
from tests.support.live_predictor import PROGRAM_OF, START_NS, station_text
from tests.support.live_recorder import (
    RunningRecorder,
    free_port,
    has_subscribers,
    wait_until,
    write_station_file,
)
from tests.support.paths import DBC_FILE
from tests.support.synthetic_runs import staircase

WAIT_S = 10.0
TOOL_ID = 4242  # the tool of the recorder's good run: its wear must be in the ledger
_buses = itertools.count()


class _Target:
    """Two peer sessions on loopback (served, feeding) and a publisher per channel."""

    station = "st1"
    channels: tuple[str, ...] = ()

    def __init__(self) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.served = zenoh.open(zenoh_config("peer", listen=[self.endpoint]))
        self.feeding = zenoh.open(zenoh_config("peer", connect=[self.endpoint]))
        self._publishers: dict[str, zenoh.Publisher] = {}
        self.sent = 0  # payloads sent
        self.refusals = 0  # of them, those that must be refused

    def send(self, channel: str, payload: bytes, refuse: bool = False) -> None:
        """Put ``payload`` on the channel; ``refuse``: the service must refuse and count it."""
        self.publisher(channel).put(payload)
        self.sent += 1
        self.refusals += refuse

    def refused(self) -> int:
        """Payloads the service counted as refused."""
        raise NotImplementedError

    def alive(self) -> bool:
        raise NotImplementedError

    def wait_handled(self) -> None:
        """Until every payload sent so far was handled (the service counts as it goes)."""
        wait_until(lambda: self.refused() >= self.refusals, "the refused payloads counted", WAIT_S)

    def publisher(self, channel: str) -> zenoh.Publisher:
        publisher = self._publishers.get(channel)
        if publisher is None:
            publisher = self.feeding.declare_publisher(
                keys.station_key(self.station, channel),
                congestion_control=zenoh.CongestionControl.BLOCK,
            )
            wait_until(lambda: has_subscribers(publisher), f"a subscriber of {channel}", WAIT_S)
            self._publishers[channel] = publisher
        return publisher

    def close(self) -> None:
        for publisher in self._publishers.values():
            publisher.undeclare()
        self.feeding.close()
        self.served.close()

    def __enter__(self) -> Any:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


class _Outlet:
    """The acquisition's output, kept (samples are not what is fuzzed here)."""

    def __init__(self) -> None:
        self.states: list[ToolState] = []

    def sample(self, sample: Sample) -> None:
        pass

    def tool_state(self, state: ToolState) -> None:
        self.states.append(state)

    def bus_stats(self, stats: BusStats) -> None:
        pass


class AcquisitionTarget(_Target):
    channels = (channels.DECISION.topic,)

    def __init__(self) -> None:
        super().__init__()
        channel = f"fuzz-acquisition-{next(_buses)}"
        self.tool = can.Bus(interface="virtual", channel=channel)
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.database = StationDatabase(DBC_FILE)
        self.outlet = _Outlet()
        self.acquisition = Acquisition(self.station, True, self.bus, self.database, self.outlet)
        self.subscriber = self.served.declare_subscriber(
            channels.DECISION.key(self.station), decision_handler(self.acquisition)
        )
        self._stop = threading.Event()
        self._loop = threading.Thread(target=self._poll, daemon=True)
        self._loop.start()
        self.run_id = 1000
        self._start_run()

    def _poll(self) -> None:
        while not self._stop.is_set():
            self.acquisition.poll(0.01)

    def _start_run(self) -> None:
        self.run_id += 1
        data = self.database.encode(
            "ToolStatus", {"RunId": self.run_id, "ToolId": 3, "ProgramId": 1, "State": 1}
        )
        self.tool.send(can.Message(arbitration_id=0x80, data=data, is_extended_id=False))
        wait_until(
            lambda: any(s.run_id == self.run_id for s in self.outlet.states), "the run", WAIT_S
        )

    def refused(self) -> int:
        return self.acquisition.stats().bad_decisions

    def alive(self) -> bool:
        return self._loop.is_alive()

    def prove_serving(self) -> None:
        """A good decision for a new run stops the tool: one StopCommand, that run's."""
        while self.tool.recv(0) is not None:
            pass
        assert self.acquisition.stats().stop_commands == 0, "a bad decision stopped the tool"
        self._start_run()
        now = time.time_ns()
        good = StopDecision(self.station, self.run_id, now, 0.5, "plateau_closest", "", 1.0,
                            None, None, now)  # fmt: skip
        self.send(channels.DECISION.topic, encode(good))
        deadline = time.monotonic() + WAIT_S
        while time.monotonic() < deadline:
            frame = self.tool.recv(0.1)
            if frame is not None and frame.arbitration_id == self.database.stop_command_id:
                signals = self.database.decode(frame.arbitration_id, frame.data)
                assert (signals["RunId"], signals["Reason"]) == (self.run_id, 1)
                return
        raise AssertionError("a good decision after the bad ones sent no StopCommand")

    def close(self) -> None:
        self._stop.set()
        self._loop.join(5.0)
        self.subscriber.undeclare()
        super().close()
        self.bus.shutdown()
        self.tool.shutdown()


class PredictorTarget(_Target):
    station = "pt1"
    channels = (channels.SAMPLES.topic, channels.TOOL.topic, channels.PART.topic)

    def __init__(self, folder: Path) -> None:
        super().__init__()
        path = folder / "pt1.toml"
        path.write_text(station_text(folder, "pt1", PROGRAM_OF["pt1"], self.endpoint))
        self.skeleton = ServiceSkeleton("predictor", self.served)
        self.service = PredictorService(self.skeleton, load_line([path]))
        self._stop = threading.Event()
        self._worker = threading.Thread(target=self.service.work, args=(self._stop,), daemon=True)
        self._worker.start()
        self.run_id = 100

    def refused(self) -> int:
        return self.service.bad_payloads

    def alive(self) -> bool:
        return self._worker.is_alive()

    def prove_serving(self) -> None:
        """A whole good run is still decided (plateau_closest, as without the fuzz)."""
        self.run_id += 1
        decisions = self.feeding.declare_subscriber(
            channels.DECISION.key(self.station), zenoh.handlers.FifoChannel(100)
        )
        try:
            self.send(channels.TOOL.topic, encode(self._state("running", START_NS)))
            for i, row in enumerate(staircase(torque_noise_nm=0.2, force_noise_n=30.0).rows()):
                t, torque, force, angle = row
                sample = Sample(self.station, self.run_id, i, START_NS + round(t * 1e9), torque,
                                angle, force)  # fmt: skip
                self.send(channels.SAMPLES.topic, encode(sample))
            self.send(channels.TOOL.topic, encode(self._state("done", START_NS + 2_000_000_000)))
            deadline = time.monotonic() + WAIT_S
            heard = decisions.try_recv()
            while heard is None and time.monotonic() < deadline:
                time.sleep(0.01)
                heard = decisions.try_recv()
        finally:
            decisions.undeclare()
        assert heard is not None, "a good run after the bad payloads was not decided"
        decision = decode(StopDecision, heard.payload.to_bytes())
        assert (decision.run_id, decision.reason) == (self.run_id, "plateau_closest")

    def _state(self, name: str, at_ns: int) -> ToolState:
        return ToolState(self.station, self.run_id, 3, PROGRAM_OF["pt1"], name, at_ns)  # type: ignore[arg-type]

    def close(self) -> None:
        self._stop.set()
        self.service.wake()
        self._worker.join(5.0)
        self.skeleton.close()  # the service's declarations, then the served session
        super().close()


class RecorderTarget(_Target):
    #: every key the recorder decodes
    channels = tuple(channel.topic for channel in CHANNELS)

    def __init__(self, folder: Path) -> None:  # no served session: the recorder opens its own
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        path = write_station_file(folder / "st1.toml", folder / "recordings", [self.endpoint])
        self.loaded = load_station(path)
        self.running = RunningRecorder(self.loaded)
        self.feeding = zenoh.open(zenoh_config("peer", connect=[self.endpoint]))
        self._publishers = {}
        self.sent = self.refusals = 0
        self.refused_payloads: list[tuple[str, bytes]] = []
        self.run_id = 500

    def send(self, channel: str, payload: bytes, refuse: bool = False) -> None:
        super().send(channel, payload, refuse)
        if refuse:  # kept to find it in the raw channel later
            self.refused_payloads.append((keys.station_key(self.station, channel), payload))
        elif channel == channels.SAMPLE_BATCHES.topic:  # written as the samples it holds
            self.sent += len(json.loads(payload)["samples"]) - 1

    def refused(self) -> int:
        return self.running.service.recorder.refused[self.station]

    def recorded(self) -> int:
        return self.running.service.recorder.messages

    def wait_handled(self) -> None:
        """Every payload recorded and every refusal counted: the recorder also records what
        it puts itself (its stats, its alerts), so the first alone can hold too early."""
        wait_until(
            lambda: self.recorded() >= self.sent and self.refused() >= self.refusals,
            "every payload recorded and every refusal counted",
            WAIT_S,
        )

    def alive(self) -> bool:
        return self.running.thread.is_alive()

    def query_wear(self, parameters: str = "", payload: bytes | None = None) -> list[Any]:
        """Replies of ``boltwatch/st1/wear`` to one query (ok payloads or error texts)."""
        key = keys.station_key(self.station, keys.WEAR)
        selector = f"{key}?{parameters}" if parameters else key
        replies = self.feeding.get(selector, payload=payload, timeout=WAIT_S)
        out: list[Any] = []
        for reply in replies:
            if reply.ok is not None:
                out.append(json.loads(reply.ok.payload.to_bytes()))
            elif reply.err is not None:
                out.append(reply.err.payload.to_bytes())
        return out

    def prove_serving(self) -> None:
        """A good run after the fuzz is recorded; the wear query still answers."""
        self.run_id += 1
        now = time.time_ns()
        good: list[tuple[str, Any]] = [
            ("tool", ToolState(self.station, self.run_id, 3, 1, "running", now))
        ]
        good += [
            ("samples", Sample(self.station, self.run_id, n, now + n, 1.0, 2.0, 3.0))
            for n in range(20)
        ]
        good.append(("tool", ToolState(self.station, self.run_id, 3, 1, "done", now + 20)))
        summary = template(channels.RUNS.topic, self.station, now + 20, self.run_id)
        good.append(  # a summary the wear ledger takes: within what its run can carry
            (
                channels.RUNS.topic,
                replace(
                    summary,
                    tool_id=TOOL_ID,
                    process_intensity=1.5,
                    events=5,
                    samples=20,
                    started_ns=now,
                    ended_ns=now + 1_000_000_000,
                ),
            )
        )
        for channel, message in good:
            self.send(channel, encode(message))
        wait_until(lambda: self.recorded() == self.sent, "the good run recorded", WAIT_S)
        wait_until(self._tool_in_ledger, "the good run's tool in the wear query's answer", WAIT_S)

    def _tool_in_ledger(self) -> bool:
        """Whether the wear query answers with the good run's tool (the summary is written
        into the ledger after it is recorded; a ledger being made answers with an error)."""
        (reply,) = self.query_wear()
        return isinstance(reply, dict) and TOOL_ID in [tool["tool_id"] for tool in reply["tools"]]

    def read_back(self) -> tuple[list[tuple[str, bytes]], dict[str, list[Any]]]:
        """Stop the recorder; (raw messages, typed messages by topic) of every file."""
        self.running.finish()
        raw: list[tuple[str, bytes]] = []
        typed: dict[str, list[Any]] = {}
        files = self.loaded.recordings_folder.glob("st1/*/*.mcap")
        for path in sorted(files, key=_first_log_time_ns):  # in the order they were written
            with path.open("rb") as handle:
                for _, channel, message in make_reader(handle).iter_messages(log_time_order=False):
                    if channel.message_encoding == RAW_ENCODING:
                        raw.append((channel.topic, message.data))
                    else:
                        typed.setdefault(channel.topic, []).append(json.loads(message.data))
        return raw, typed

    def close(self) -> None:
        self.running.finish()
        for publisher in self._publishers.values():
            publisher.undeclare()
        self.feeding.close()


def _first_log_time_ns(path: Path) -> int:
    """When the first message of a complete file was received (an idle file between two runs
    sorts between them, whatever its name)."""
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    statistics = None if summary is None else summary.statistics
    return 0 if statistics is None else statistics.message_start_time
