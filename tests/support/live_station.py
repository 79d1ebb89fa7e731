"""A whole simulated station as real processes, watched from zenoh and from the CAN bus.

Router, recorder, predictor and acquisition start as ``boltwatch serve``
processes (through :class:`StationSupervisor`, logs in ``<tmp>/logs``); the
rig runs program 2 (short runs) until stopped. The test sees the station
twice: on zenoh (run summaries, decisions) and on the CAN bus itself
(:class:`CanWatch`: what the tool really did, run by run, even while the
acquisition is dead). Services can be killed with SIGKILL and started again,
as compose ``restart:`` or systemd would.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import threading
import time
from collections import defaultdict
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import can
import zenoh
from mcap.records import Channel, Message, Schema

from services.cli.station_supervisor import ManagedProcess, StationSupervisor
from shared.config import LoadedStation, load_station
from shared.contract import (
    RunSummary,
    StationDatabase,
    ToolRunState,
    channels,
    keys,
)
from shared.errors import InputError, TransportError
from shared.recordings import final_path_of, unfinished_files
from shared.recordings.mcap import RecordingScan
from shared.runtime import open_bus, open_from, zenoh_config
from tests.support.listener import Listener
from tests.support.station_files import write_station

STATION = "st1"
PROGRAM = 2
START_TIMEOUT_S = 30.0
SERVICES = ("recorder", "predictor", "acquisition")


@dataclass
class RunOnBus:
    """One run as the CAN bus carried it."""

    run_id: int
    states: list[ToolRunState] = field(default_factory=list)
    forces_n: list[float] = field(default_factory=list)

    @property
    def ended(self) -> bool:
        return any(state in (ToolRunState.DONE, ToolRunState.ABORTED) for state in self.states)


class CanWatch:
    """Listens to ToolStatus and JointSensors on the station bus, from a thread."""

    def __init__(self, loaded: LoadedStation) -> None:
        self._database = StationDatabase(loaded.dbc_path)
        self._bus = open_bus(loaded.config.can)
        self._lock = threading.Lock()
        self._runs: dict[int, RunOnBus] = {}
        self._current: RunOnBus | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._listen, name="can-watch", daemon=True)
        self._thread.start()

    def runs(self) -> dict[int, RunOnBus]:
        with self._lock:
            return {
                run_id: RunOnBus(run.run_id, list(run.states), list(run.forces_n))
                for run_id, run in self._runs.items()
            }

    def _listen(self) -> None:
        status_id = self._database.tool_status_id
        joint_id = self._database.joint_sensors_id
        while not self._stop.is_set():
            try:
                message = self._bus.recv(0.05)
            except can.CanError:
                continue
            if message is None or message.arbitration_id not in (status_id, joint_id):
                continue
            signals = self._database.decode(message.arbitration_id, message.data)
            with self._lock:
                if message.arbitration_id == status_id:
                    run = self._runs.setdefault(
                        int(signals["RunId"]), RunOnBus(int(signals["RunId"]))
                    )
                    state = ToolRunState(int(signals["State"]))
                    if not run.states or run.states[-1] != state:
                        run.states.append(state)
                    self._current = run
                elif self._current is not None:
                    self._current.forces_n.append(float(signals["Force"]))

    def close(self) -> None:
        if not self._stop.is_set():
            self._stop.set()
            self._thread.join()
            self._bus.shutdown()


class LiveStation:
    """The station's processes; :meth:`close` stops them all and closes the watchers."""

    def __init__(
        self,
        folder: Path,
        recorder_args: tuple[str, ...] = ("--no-rerun",),
        placement: str = "line",
        replacements: dict[str, str] | None = None,
    ) -> None:
        """``placement``: "line" (a predictor process of its own) or "edge" (in the acquisition);
        ``replacements``: changes to the station file (:func:`write_station`)."""
        self.folder = folder
        self.placement = placement
        self.station_file = write_station(folder, placement=placement, replacements=replacements)
        self.loaded = load_station(self.station_file)
        self.recordings = self.loaded.recordings_folder
        self.supervisor = StationSupervisor(self.station_file, folder / "logs")
        self.recorder_args = recorder_args
        self.restarts: dict[str, int] = defaultdict(int)
        self.can = CanWatch(self.loaded)
        endpoint = self.loaded.config.zenoh.connect[0]
        self.supervisor.start("router", ["--listen", endpoint])
        self.session = open_client(endpoint)
        self.heard = Listener(self.session, STATION, (channels.RUNS.topic, channels.DECISION.topic))
        processes = [s for s in SERVICES if placement == "line" or s != "predictor"]
        for service in processes:
            self.start(service)
        self.wait_alive(SERVICES)  # an edge predictor's token comes from the acquisition
        self.supervisor.start("rig", ["--program", str(PROGRAM), "--first-run-id", "1000"])

    def start(self, service: str) -> ManagedProcess:
        count = self.restarts[service]
        self.restarts[service] += 1
        extra = self.recorder_args if service == "recorder" else ()
        name = service if count == 0 else f"{service}-{count + 1}"
        return self.supervisor.start(service, extra, name=name)

    def process(self, service: str) -> ManagedProcess:
        count = self.restarts[service]
        return self.supervisor.find(service if count <= 1 else f"{service}-{count}")

    def kill(self, service: str) -> None:
        managed = self.process(service)
        os.kill(managed.pid, signal.SIGKILL)
        managed.process.wait(10)

    def log(self, service: str) -> str:
        return self.process(service).log_path.read_text(errors="replace")

    def wait_alive(self, services: tuple[str, ...]) -> None:
        def alive() -> bool:
            seen = {
                str(reply.ok.key_expr).rsplit("/", 1)[-1]
                for reply in self.session.liveliness().get(keys.health_key(STATION, "*"))
                if reply.ok is not None
            }
            return set(services) <= seen

        self.wait_for(alive, f"{', '.join(services)} alive")

    def wait_for(
        self,
        condition: Callable[[], bool],
        what: str,
        timeout_s: float = 30.0,
        poll_s: float = 0.05,
        details: Callable[[], str] | None = None,
    ) -> None:
        """Poll ``condition`` (:func:`wait_supervised`; ``details()`` said when it gives up)."""
        wait_supervised(self.supervisor, condition, what, timeout_s, poll_s, details=details)

    def summaries(self) -> list[RunSummary]:
        return self.heard.of(channels.RUNS.topic)

    def decided(self, run_id: int) -> bool:
        return any(d.run_id == run_id for d in self.heard.of(channels.DECISION.topic))

    def wait_runs_summarised(self, count: int, timeout_s: float = 30.0) -> list[RunSummary]:
        self.wait_for(lambda: len(self.summaries()) >= count, f"{count} run summaries", timeout_s)
        return self.summaries()

    def running_run(self) -> int | None:
        """The run the bus says is running now, if any."""
        for run in self.can.runs().values():
            if run.states and run.states[-1] == ToolRunState.RUNNING:
                return run.run_id
        return None

    def close(self) -> None:
        """Stop the rig first, the recorder last (so its files are complete), then the rest."""
        self.heard.close()
        self.session.close()
        names = [m.name for m in self.supervisor.processes]
        order = [
            n
            for s in ("rig", "acquisition", "predictor", "recorder")
            for n in names
            if n.startswith(s)
        ]
        self.supervisor.stop_all([*order, "router"])
        self.can.close()


def wait_supervised(
    supervisor: StationSupervisor,
    condition: Callable[[], bool],
    what: str,
    timeout_s: float = 30.0,
    poll_s: float = 0.05,
    exits: Collection[int] = (-signal.SIGKILL,),
    details: Callable[[], str] | None = None,
) -> None:
    """Poll ``condition`` until true; AssertionError as soon as one of ``supervisor``'s
    processes exits with a code not in ``exits`` (SIGKILL: a test's own kill), or naming
    ``what`` (and ``details()``) after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        for managed in supervisor.processes:
            code = managed.exit_code()
            if code is not None and code not in exits:
                raise AssertionError(f"{managed.name} exited {code}:\n{managed.log_tail()}")
        if time.monotonic() > deadline:
            said = f": {details()}" if details is not None else ""
            raise AssertionError(f"gave up waiting for {what}{said}")
        time.sleep(poll_s)


def open_client(endpoint: str) -> zenoh.Session:
    """A client session to the router at ``endpoint``, retried while the router starts."""
    deadline = time.monotonic() + START_TIMEOUT_S
    while True:
        try:
            return open_from(zenoh_config("client", [endpoint], connect_timeout_ms=500))
        except TransportError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)


@contextlib.contextmanager
def live_station(
    folder: Path,
    recorder_args: tuple[str, ...] = ("--no-rerun",),
    placement: str = "line",
    replacements: dict[str, str] | None = None,
) -> Iterator[LiveStation]:
    station = LiveStation(folder, recorder_args, placement, replacements)
    try:
        yield station
    finally:
        station.close()


def recorded_sequences(recordings: Path, run_id: int) -> list[int]:
    """Sequences of the run's samples in every file under ``recordings`` (damaged or open
    files too, under their writing names: their complete records), in file order."""
    writing = unfinished_files(recordings)  # first: one renamed meanwhile is a run file next
    files = sorted(recordings.rglob("*.mcap"))
    files += [path for path in writing if final_path_of(path) not in files]
    sequences: list[int] = []
    for path in sorted(files, key=lambda path: final_path_of(path) or path):
        if path.name.endswith(".recovered.mcap"):
            continue
        for schema, _, message in _samples(path):
            if schema is not None and json.loads(message.data)["run_id"] == run_id:
                sequences.append(message.sequence)
    return sequences


def _samples(path: Path) -> Iterator[tuple[Schema | None, Channel, Message]]:
    """The sample messages of ``path``; when it was a writing name renamed (its file closed)
    since it was listed, those of its run file (none: removed, it held no message)."""
    final = final_path_of(path)
    try:
        yield from RecordingScan(path).messages("/samples")
    except InputError:
        if final is None or path.exists():
            raise
        if final.exists():
            yield from RecordingScan(final).messages("/samples")


def check_next_run_normal(station: LiveStation) -> int:
    """The first run that starts from now on is decided, summarised and fully recorded."""
    after = max(station.can.runs()) + 1  # a run that starts once the service is back
    station.wait_for(lambda: after in station.can.runs(), f"run {after} to start")
    summary = None

    def summarised() -> bool:
        nonlocal summary
        summary = next((s for s in station.summaries() if s.run_id == after), None)
        return summary is not None

    station.wait_for(summarised, f"the summary of run {after}")
    assert summary is not None
    assert station.decided(after) and summary.stop_reason is not None, summary
    assert summary.tool_state == "done"
    station.wait_for(
        lambda: len(recorded_sequences(station.recordings, after)) == summary.samples,
        f"every sample of run {after} recorded",
    )
    assert recorded_sequences(station.recordings, after) == list(range(summary.samples))
    return after
