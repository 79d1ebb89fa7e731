"""A run through the Rerun sink becomes a real ``.rrd`` that ``rerun rrd verify`` accepts.

No zenoh and no mocks: payloads are classified as the recorder classifies
them, written by the real rerun SDK, checked by the real ``rerun`` CLI and
read back with :class:`rerun.chunk.RrdReader`.
"""

from __future__ import annotations

import subprocess
import sys
from collections import Counter
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from rerun.chunk import RrdReader
from test_recording import run_messages  # type: ignore[import-not-found]  # sibling test module

from services.recorder import rerun_blueprint as bp
from services.recorder.file_metadata import FileMetadata
from services.recorder.incoming import Received, classify
from services.recorder.recorder import Recorder
from services.recorder.rerun_sink import RerunOptions, RerunSink
from services.recorder.run_files import FileLimits
from services.recorder.testing import write_station_file
from shared import keys
from shared.codec import encode
from shared.config import LoadedStation, load_station
from shared.messages import Prediction, StickSlipEvent

RERUN_CLI = Path(sys.executable).parent / "rerun"
SAMPLES = 1234  # not a multiple of the batch: the tail goes out at close
EVENTS = SAMPLES // 100  # run_messages: one event every 100 samples


def verify(path: Path) -> None:
    """``rerun rrd verify`` exits 0 on the file (its output shown on failure)."""
    result = subprocess.run(
        [str(RERUN_CLI), "rrd", "verify", str(path)], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stdout + result.stderr


def rows_by_entity(path: Path) -> Counter[str]:
    """Temporal rows per entity path of the file's recording (static styles left out)."""
    rows: Counter[str] = Counter()
    for chunk in RrdReader(path).stream():
        if not chunk.is_static:
            rows[chunk.entity_path] += chunk.num_rows
    return rows


def station(tmp_path: Path) -> LoadedStation:
    """A station file (never opened on zenoh here) recording under ``tmp_path/rec``."""
    path = write_station_file(tmp_path / "station.toml", tmp_path / "rec", ["tcp/127.0.0.1:1"])
    return load_station(path)


def received(run_id: int, items: list[tuple[str, Any]], t0_ns: int = 0) -> list[Received]:
    return [
        classify(keys.station_key("st1", topic), encode(message), t0_ns + n * 1_000_000)
        for n, (topic, message) in enumerate(items)
    ]


def with_predictions(items: list[tuple[str, Any]]) -> list[tuple[str, Any]]:
    """The run with two predicted events on every StickSlipEvent."""
    out: list[tuple[str, Any]] = []
    for topic, message in items:
        if isinstance(message, StickSlipEvent):
            predictions = [
                Prediction(h, message.time_s + 0.1 * h, 100.0 + h, 20_000.0 + 500 * h)
                for h in (1, 2)
            ]
            out.append((topic, replace(message, predictions=predictions)))
        else:
            out.append((topic, message))
    return out


def test_a_run_becomes_a_verified_rrd_with_every_sample(tmp_path: Path) -> None:
    items = with_predictions(run_messages(1, SAMPLES))
    path = tmp_path / "st1_run1_000000.rrd"
    started_ns = items[0][1].time_ns
    with RerunSink(path, "st1", 1, started_ns, RerunOptions(batch_samples=100)) as sink:
        for item in received(1, items):
            sink.write(item)
            if item.sequence == 600:
                sink.flush()  # a flush tick mid-run
    assert not sink.failed and sink.samples == SAMPLES

    verify(path)
    reader = RrdReader(path)
    (recording,) = reader.recordings()
    assert (recording.application_id, recording.recording_id) == ("boltwatch", "st1/run1")
    assert len(reader.blueprints()) == 1  # the layout travels with the file
    rows = rows_by_entity(path)
    assert rows[f"/{bp.TORQUE}"] == rows[f"/{bp.ANGLE}"] == SAMPLES
    assert rows[f"/{bp.FORCE}"] == SAMPLES - len(range(0, SAMPLES, 50))  # force None every 50
    for entity in (bp.PEAKS, bp.PLATEAUS, bp.F_SS, *bp.K_PATHS, bp.PROCESS_INTENSITY):
        assert rows[f"/{entity}"] == EVENTS, entity
    assert rows[f"/{bp.PREDICTED_PEAKS}"] == rows[f"/{bp.PREDICTED_PLATEAUS}"] == 2 * EVENTS
    assert rows[f"/{bp.TORQUE_STOP}"] == rows[f"/{bp.FORCE_STOP}"] == 1
    assert rows[f"/{bp.LOG}"] == 4  # running, stop decision, done, run summary


def test_the_recorder_writes_one_rrd_beside_each_run_mcap(tmp_path: Path) -> None:
    loaded = station(tmp_path)
    limits = FileLimits(1_000_000_000, 1 << 30, 3600 * 1_000_000_000, late_grace_ns=0)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), RerunOptions())
    run1, run2 = run_messages(1, 300), run_messages(2, 10)
    for item in received(1, run1) + received(2, run2, t0_ns=10_000_000_000):
        recorder.write(item)
    closed = recorder.close()

    mcaps = sorted(path for path in closed if path.suffix == ".mcap")
    assert len(mcaps) == 2
    for mcap, run_id, samples in zip(mcaps, (1, 2), (300, 10), strict=True):
        rrd = mcap.with_suffix(".rrd")
        verify(rrd)
        (recording,) = RrdReader(rrd).recordings()
        assert recording.recording_id == f"st1/run{run_id}"
        assert rows_by_entity(rrd)[f"/{bp.TORQUE}"] == samples


def test_a_failing_rerun_sink_leaves_the_mcap_file_whole(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    loaded = station(tmp_path)
    limits = FileLimits(1_000_000_000, 1 << 30, 3600 * 1_000_000_000)
    # The run's .rrd path is taken by a directory: Rerun cannot create the file.
    day = loaded.recordings_folder / "st1" / "1970-01-01"
    (day / "st1_run1_000000.rrd").mkdir(parents=True)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), RerunOptions())
    items = received(1, run_messages(1, 300))
    for item in items:
        recorder.write(item)
    (mcap,) = recorder.close()

    assert mcap == day / "st1_run1_000000.mcap"
    assert recorder.messages == len(items)
    assert any("Rerun" in record.getMessage() for record in caplog.records)
    from mcap.reader import make_reader

    with mcap.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count == len(items)
