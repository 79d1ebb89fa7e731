"""Drive an in-process :class:`Recorder` with runs of samples on a simulated 1 kHz clock.

Also a child-process entry point: ``python -m tests.support.recorder_driver FOLDER``
records two runs into FOLDER (meant to run under an ``RLIMIT_FSIZE`` small enough
that the first run's file hits it) and prints the recorder's fault state as JSON.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import load_station
from shared.contract import Sample, ToolState, encode
from shared.recordings import FileMetadata, Received, classify, unfinished_files
from shared.recordings.mcap import RecordingScan
from tests.support.live_recorder import write_station_file

MS = 1_000_000
T0_NS = 1_800_000_000 * 1_000_000_000


class RecorderDriver:
    """A Recorder on ``recordings`` and a clock; ``now_ns`` advances 1 ms per sample.

    ``batch_samples`` > 1: samples are filed as an edge station's batches are
    (:meth:`Recorder.write_samples`, that many at once).
    """

    def __init__(
        self, folder: Path, recordings: Path, batch_samples: int = 1, reserve_bytes: int = 0
    ) -> None:
        """``reserve_bytes``: the free-space reserve (``recorder.free_space_reserve_bytes``)."""
        loaded = load_station(
            write_station_file(folder / "station.toml", recordings, listen=["tcp/127.0.0.1:1"])
        )
        limits = FileLimits(
            1000 * MS, 1 << 40, 3600 * 1000 * MS, free_space_reserve_bytes=reserve_bytes
        )
        self.recorder = Recorder(recordings, limits, FileMetadata(loaded))
        self.now_ns = T0_NS
        self.sequence = 0
        self.batch_samples = batch_samples
        self._batch: list[Received] = []

    def start_run(self, run_id: int) -> None:
        self.sequence = 0
        self._put("tool", encode(ToolState("st1", run_id, 7, 1, "running", self.now_ns)))

    def samples(self, run_id: int, count: int) -> None:
        for _ in range(count):
            self.now_ns += MS
            sample = Sample("st1", run_id, self.sequence, self.now_ns, 1.0, 0.1, 2.0)
            if self.batch_samples == 1:
                self._put("samples", encode(sample))
            else:
                self._batch.append(classify("boltwatch/st1/samples", encode(sample), self.now_ns))
                if len(self._batch) == self.batch_samples:
                    self.recorder.write_samples("st1", self._batch)
                    self._batch = []
            self.sequence += 1
            if self.sequence % 500 == 0:
                self.recorder.tick(self.now_ns)

    def end_run(self, run_id: int) -> None:
        self._put("tool", encode(ToolState("st1", run_id, 7, 1, "done", self.now_ns)))

    def _put(self, topic: str, payload: bytes) -> None:
        self.recorder.write(classify(f"boltwatch/st1/{topic}", payload, self.now_ns))


def recorded_messages(recordings: Path) -> int:
    """Messages readable in every MCAP file under ``recordings``, and in the files left under
    their writing name (a fault's that could not be finished: the next start does)."""
    files = [*recordings.rglob("*.mcap"), *unfinished_files(recordings)]
    return sum(1 for path in files for _ in RecordingScan(path).messages())


def main(folder: Path) -> None:
    driver = RecorderDriver(folder, folder / "recordings")
    driver.start_run(1)
    driver.samples(1, 8000)  # ~250 kB: beyond the file size limit
    driver.end_run(1)
    driver.start_run(2)
    driver.samples(2, 1000)  # ~35 kB: fits in a new file
    driver.end_run(2)
    recorder = driver.recorder
    closed = recorder.close()
    state = {
        "write_errors": recorder.write_errors,
        "last_write_error": recorder.last_write_error,
        "recording_ok": recorder.recording_ok,
        "dropped_messages": recorder.dropped_messages,
        "messages": recorder.messages,
        "closed": [str(path) for path in closed],
    }
    print(json.dumps(state))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
