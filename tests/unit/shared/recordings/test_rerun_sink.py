"""A run through the Rerun sink becomes a real ``.rrd`` that ``rerun rrd verify`` accepts.

No zenoh and no mocks: payloads are classified as the recorder classifies
them, written by the real rerun SDK, checked by the real ``rerun`` CLI and
read back with :class:`rerun.chunk.RrdReader`.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import warnings
from collections import Counter
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from rerun.chunk import RrdReader

from services.cli.main import main
from services.cli.station_supervisor import stop_process
from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import LoadedStation, load_station
from shared.contract import Prediction, StickSlipEvent, encode, keys
from shared.recordings import FileMetadata, Received, classify
from shared.recordings.rerun import BLUEPRINT_FILE, RerunLive, RerunOptions, RerunSink
from shared.recordings.rerun import rerun_blueprint as bp
from tests.support.live_recorder import free_port, wait_until, write_station_file
from tests.support.recorded_runs import T0_NS, run_messages

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
    """The run's messages as received from ``T0_NS + t0_ns`` on, one a millisecond (messages
    ahead of their arrival by more than a few minutes would be refused)."""
    return [
        classify(keys.station_key("st1", topic), encode(message), T0_NS + t0_ns + n * 1_000_000)
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
    assert recording.application_id == "boltwatch"
    assert recording.recording_id.startswith("st1")  # pooled streams: rerun_streams.py
    layout = RrdReader(tmp_path / BLUEPRINT_FILE)  # the layout of the folder's runs
    assert len(layout.blueprints()) == 1 and not layout.recordings()
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
    for mcap, samples in zip(mcaps, (300, 10), strict=True):
        rrd = mcap.with_suffix(".rrd")
        verify(rrd)
        (recording,) = RrdReader(rrd).recordings()
        assert recording.recording_id.startswith("st1")  # pooled streams: rerun_streams.py
        assert rows_by_entity(rrd)[f"/{bp.TORQUE}"] == samples


def test_a_run_recorded_as_mcap_only_gets_the_live_rrd_from_its_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``inspect RUN.mcap --rerun`` writes what the recorder writes live, row for row."""
    loaded = station(tmp_path)
    limits = FileLimits(1_000_000_000, 1 << 30, 3600 * 1_000_000_000, late_grace_ns=0)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), RerunOptions())
    for item in received(1, with_predictions(run_messages(1, SAMPLES))):
        recorder.write(item)
    (mcap,) = [path for path in recorder.close() if path.suffix == ".mcap"]
    made = tmp_path / "made" / "run1.rrd"
    made.parent.mkdir()

    assert main(["inspect", str(mcap), "--rerun", "--out", str(made)]) == 0
    verify(made)
    live = mcap.with_suffix(".rrd")
    assert rows_by_entity(made) == rows_by_entity(live)
    assert rows_by_entity(made)[f"/{bp.TORQUE}"] == SAMPLES
    assert (made.parent / BLUEPRINT_FILE).is_file()
    assert f"wrote {made}: run 1 of st1, {SAMPLES} samples, {EVENTS} stick-slip events" in (
        capsys.readouterr().out
    )
    assert main(["inspect", str(mcap), "--rerun"]) == 2  # the live one is there: not replaced
    assert "exists" in capsys.readouterr().err


def test_a_failing_rerun_sink_leaves_the_mcap_file_whole(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    loaded = station(tmp_path)
    limits = FileLimits(1_000_000_000, 1 << 30, 3600 * 1_000_000_000)
    # The run's .rrd path is taken by a directory: Rerun cannot create the file.
    day = loaded.recordings_folder / "st1" / "2023-11-14"  # T0_NS is 2023-11-14T22:13:20Z
    (day / "st1_run1_221320.rrd").mkdir(parents=True)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), RerunOptions())
    items = received(1, run_messages(1, 300))
    for item in items:
        recorder.write(item)
    (mcap,) = recorder.close()

    assert mcap == day / "st1_run1_221320.mcap"
    assert recorder.messages == len(items)
    assert any("Rerun" in record.getMessage() for record in caplog.records)
    from mcap.reader import make_reader

    with mcap.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count == len(items)


@pytest.mark.filterwarnings("ignore:RRD file has no footer")
def test_a_cut_rrd_is_reported_and_its_complete_chunks_recovered(tmp_path: Path) -> None:
    """As a kill -9 leaves it: no footer. verify says so; recover keeps what is whole."""
    from shared.errors import InputError
    from shared.recordings.rerun import check_rrd, recover_rrd, rows_by_entity

    whole = tmp_path / "st1_run1_000000.rrd"
    items = run_messages(1, 3000)
    with RerunSink(whole, "st1", 1, items[0][1].time_ns, RerunOptions(batch_samples=250)) as sink:
        for n, item in enumerate(received(1, items)):
            sink.write(item)
            if n % 500 == 0:
                sink.flush()  # the recorder's flush ticks
    data = whole.read_bytes()
    assert check_rrd(whole).ok
    whole_rows = rows_by_entity(whole)
    assert whole_rows[f"/{bp.TORQUE}"] == 3000

    recovered_samples = []
    for fraction in (0.3, 0.6, 0.95, 0.999):
        cut = tmp_path / f"cut{fraction}.rrd"
        cut.write_bytes(data[: int(len(data) * fraction)])
        check = check_rrd(cut)
        assert not check.ok and check.problem is not None
        assert "Missing RRD footer" in check.problem
        with pytest.raises(RuntimeError, match="exceeds file size"):  # the SDK alone: nothing
            list(RrdReader(cut).stream())
        recovery = recover_rrd(cut)
        verify(recovery.target)
        assert recovery.damage == check.problem
        assert 0 < recovery.samples <= 3000
        assert sum(recovery.rows_by_entity.values()) <= sum(whole_rows.values())
        assert str(cut) in recovery.describe() and "damaged: Missing RRD footer" in (
            recovery.describe()
        )
        recovered_samples.append(recovery.samples)
    assert recovered_samples == sorted(recovered_samples)  # more file, more samples
    assert recovered_samples[0] < 3000  # a cut early in the run loses its tail

    header_only = tmp_path / "cut_header.rrd"
    header_only.write_bytes(data[:10])
    assert not check_rrd(header_only).ok  # rerun rrd verify itself exits 0 on it
    with pytest.raises(InputError, match=r"cut_header\.rrd: (nothing readable|no complete chunk)"):
        recover_rrd(header_only)
    assert not (tmp_path / "cut_header.recovered.rrd").exists()


@pytest.mark.filterwarnings("ignore:RRD file has no footer")
def test_boltwatch_recover_takes_a_cut_rrd(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from services.cli.main import build_parser

    whole = tmp_path / "st1_run1_000000.rrd"
    items = run_messages(1, 1000)
    with RerunSink(whole, "st1", 1, items[0][1].time_ns, RerunOptions(batch_samples=250)) as sink:
        for item in received(1, items):
            sink.write(item)
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size * 3 // 4])
    args = build_parser().parse_args(["recover", str(cut)])
    assert args.handler(args) == 0
    verify(tmp_path / "cut.recovered.rrd")
    assert "Missing RRD footer" in capsys.readouterr().out


def test_live_only_streams_every_sample_to_the_viewer_and_writes_no_file(
    tmp_path: Path,
) -> None:
    """``--no-rerun --rerun-web`` (docker-compose's viewer): the run reaches the live
    server whole, and no ``.rrd`` or layout file is written."""
    live = RerunLive(free_port())
    saved = tmp_path / "saved.rrd"
    try:
        items = run_messages(1, SAMPLES)
        options = RerunOptions(live_url=live.url, write_files=False)
        path = tmp_path / "runs" / "st1_run1_000000.rrd"
        with RerunSink(path, "st1", 1, items[0][1].time_ns, options) as sink:
            for item in received(1, items):
                sink.write(item)
        assert not sink.failed and not (tmp_path / "runs").exists()
        # a late viewer: the server keeps what it was sent for viewers that connect later
        viewer = subprocess.Popen(
            [str(RERUN_CLI), live.url, "--save", str(saved), "--port", str(free_port())],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            wait_until(lambda: samples_saved(saved) == SAMPLES, "the run saved from the server")
        finally:
            viewer.send_signal(signal.SIGINT)
            stop_process(viewer)
    finally:
        live.close()


def samples_saved(path: Path) -> int:
    """Torque rows of the ``st1`` recording saved so far (0 while there is none)."""
    if not path.exists() or path.stat().st_size == 0:
        return 0
    try:
        with warnings.catch_warnings():  # no footer yet: the viewer is still writing it
            warnings.simplefilter("ignore")
            reader = RrdReader(path)
        runs = [r for r in reader.recordings() if r.recording_id.startswith("st1")]
        if not runs:
            return 0
        return sum(
            chunk.num_rows
            for chunk in reader.stream(store=runs[0])
            if chunk.entity_path == f"/{bp.TORQUE}" and not chunk.is_static
        )
    except Exception:  # a file still being written may end mid-message
        return 0
