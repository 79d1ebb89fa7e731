"""Run files: naming, rotation on run start and on limits, late messages of the previous run."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

from services.recorder.live.run_files import FileLimits, StationFiles
from shared.config import LoadedStation
from shared.contract import BusStats, ToolState, encode
from shared.recordings import FileMetadata, classify, file_path
from tests.support import factories

T0_NS = 1_700_000_000_000_000_000  # 2023-11-14T22:13:20Z
SECOND_NS = 1_000_000_000
LIMITS = FileLimits(
    flush_interval_ns=SECOND_NS, max_file_bytes=1 << 40, max_file_duration_ns=3600 * SECOND_NS
)


def tool(run_id: int, state: str, t_ns: int) -> bytes:
    return encode(ToolState("st1", run_id, 7, 2, state, t_ns))  # type: ignore[arg-type]


def sample(run_id: int, n: int, t_ns: int) -> bytes:
    return encode(
        factories.sample(run_id, n, time_ns=t_ns, torque_nm=1.0, angle_deg=2.0, force_n=None)
    )


def bus(t_ns: int) -> bytes:
    counters: dict[str, Any] = {field.name: 0 for field in dataclasses.fields(BusStats)}
    return encode(BusStats(**{**counters, "station": "st1", "time_ns": t_ns}))


def summary(run_id: int, t_ns: int) -> bytes:
    return encode(factories.summary(run_id, program_id=2, started_ns=t_ns, ended_ns=t_ns))


def feed(files: StationFiles, items: list[tuple[str, bytes, int]]) -> None:
    for topic, payload, t_ns in items:
        files.write(classify(f"boltwatch/st1/{topic}", payload, t_ns))


def counts(path: Path) -> dict[str, int]:
    with path.open("rb") as handle:
        found: dict[str, int] = {}
        for _, channel, _ in make_reader(handle).iter_messages(log_time_order=False):
            found[channel.topic.rsplit("/", 1)[1]] = (
                found.get(channel.topic.rsplit("/", 1)[1], 0) + 1
            )
    return found


def test_file_path_is_station_date_run_time(tmp_path: Path) -> None:
    path = file_path(tmp_path, "st1", 42, T0_NS)
    assert path == tmp_path / "st1" / "2023-11-14" / "st1_run42_221320.mcap"
    path.parent.mkdir(parents=True)
    path.touch()
    assert file_path(tmp_path, "st1", 42, T0_NS).name == "st1_run42_221320_2.mcap"
    assert file_path(tmp_path, "a/b", None, T0_NS, part=3).name == "a_b_idle_221320_part3.mcap"


def test_idle_then_runs_with_a_late_summary(tmp_path: Path, station: LoadedStation) -> None:
    files = StationFiles("st1", tmp_path, LIMITS, FileMetadata(station))
    t = T0_NS
    feed(
        files,
        [
            ("bus", bus(t), t),
            ("tool", tool(1, "running", t + 1), t + 1),
            ("samples", sample(1, 0, t + 2), t + 2),
            ("tool", tool(1, "done", t + 3), t + 3),
            ("bus", bus(t + 4), t + 4),
            ("tool", tool(2, "running", t + SECOND_NS), t + SECOND_NS),
            ("runs", summary(1, t + 3), t + SECOND_NS + 1),  # late: belongs to run 1
            ("samples", sample(2, 0, t + SECOND_NS + 2), t + SECOND_NS + 2),
        ],
    )
    files.tick(t + 10 * SECOND_NS)  # the grace of run 1's file is over
    assert len(files.closed_paths) == 2  # idle (at run 2's start) and run 1 (after grace)
    files.close()
    names = sorted(p.name for p in files.closed_paths)
    assert names == ["st1_idle_221320.mcap", "st1_run1_221320.mcap", "st1_run2_221321.mcap"]
    by_name = {p.name: counts(p) for p in files.closed_paths}
    assert by_name["st1_idle_221320.mcap"] == {"bus": 1}
    assert by_name["st1_run1_221320.mcap"] == {"tool": 2, "samples": 1, "bus": 1, "runs": 1}
    assert by_name["st1_run2_221321.mcap"] == {"tool": 1, "samples": 1}


def test_a_run_that_never_ends_continues_in_parts(tmp_path: Path, station: LoadedStation) -> None:
    limits = FileLimits(
        flush_interval_ns=SECOND_NS, max_file_bytes=1 << 40, max_file_duration_ns=10 * SECOND_NS
    )
    files = StationFiles("st1", tmp_path, limits, FileMetadata(station))
    feed(files, [("tool", tool(5, "running", T0_NS), T0_NS)])
    feed(
        files,
        [
            ("samples", sample(5, n, T0_NS + n * SECOND_NS), T0_NS + n * SECOND_NS)
            for n in range(25)
        ],
    )
    files.close()
    names = sorted(p.name for p in files.closed_paths)
    assert names == [
        "st1_run5_221320.mcap",
        "st1_run5_221330_part2.mcap",
        "st1_run5_221340_part3.mcap",
    ]
    total = sum(counts(p).get("samples", 0) for p in files.closed_paths)
    assert total == 25


def test_a_file_over_its_byte_limit_continues(tmp_path: Path, station: LoadedStation) -> None:
    limits = FileLimits(
        flush_interval_ns=SECOND_NS, max_file_bytes=20_000, max_file_duration_ns=3600 * SECOND_NS
    )
    files = StationFiles("st1", tmp_path, limits, FileMetadata(station))
    feed(files, [("tool", tool(5, "running", T0_NS), T0_NS)])
    feed(files, [("samples", sample(5, n, T0_NS + n), T0_NS + n) for n in range(1000)])
    files.close()
    assert len(files.closed_paths) > 1
    assert sum(counts(p).get("samples", 0) for p in files.closed_paths) == 1000
    assert all(p.stat().st_size < 40_000 for p in files.closed_paths)


def test_a_run_id_is_one_file_however_its_state_flips(
    tmp_path: Path, station: LoadedStation
) -> None:
    """ToolStatus flipping every 5 ms for one run id made 69 MCAP files."""
    files = StationFiles("st1", tmp_path, LIMITS, FileMetadata(station))
    t = T0_NS
    items = []
    for flip in range(30):
        t += 5_000_000
        items.append(("tool", tool(42, "running" if flip % 2 == 0 else "done", t), t))
        items.append(("samples", sample(42, flip, t + 1), t + 1))
    items.append(("tool", tool(43, "running", t + SECOND_NS), t + SECOND_NS))
    feed(files, items)
    files.close()
    names = sorted(p.name for p in files.closed_paths)
    assert names == ["st1_run42_221320.mcap", "st1_run43_221321.mcap"]
    assert counts(tmp_path / "st1" / "2023-11-14" / names[0]) == {"tool": 30, "samples": 30}


def test_a_batch_with_samples_of_the_run_before_splits_between_their_files(
    tmp_path: Path, station: LoadedStation
) -> None:
    """A batch gathered across a run's start: each sample goes to its own run's file, in
    order, as samples that came alone do."""
    files = StationFiles("st1", tmp_path, LIMITS, FileMetadata(station))
    t = T0_NS
    feed(files, [("tool", tool(1, "running", t), t), ("tool", tool(2, "running", t + 5), t + 5)])
    batch = [
        classify("boltwatch/st1/samples", sample(run_id, n, t + 10 + n), t + 20)
        for n, run_id in enumerate([1, 1, 2, 2, 1])
    ]
    files.write_samples(batch)
    files.close()
    sequences: dict[str, list[int]] = {}
    for path in files.closed_paths:
        with path.open("rb") as handle:
            found = make_reader(handle).iter_messages(log_time_order=False)
            sequences[path.name] = [m.sequence for _, c, m in found if c.topic.endswith("samples")]
    assert sequences == {"st1_run1_221320.mcap": [0, 1, 4], "st1_run2_221320.mcap": [2, 3]}
    assert files.written == 2 + 5


def test_a_runs_file_is_final_a_grace_after_its_summary_and_the_idle_time_goes_elsewhere(
    tmp_path: Path, station: LoadedStation
) -> None:
    """The station stops tightening: its last run's file is finished (under its name) a
    grace after the run's summary, with no next run; what the station says afterwards (its
    counters) goes into an idle file, which the next run's start finishes."""
    files = StationFiles("st1", tmp_path, LIMITS, FileMetadata(station))
    t = T0_NS
    feed(
        files,
        [
            ("tool", tool(1, "running", t), t),
            ("samples", sample(1, 0, t + 1), t + 1),
            ("tool", tool(1, "done", t + 2), t + 2),
            ("runs", summary(1, t + 2), t + 3),
            ("bus", bus(t + 4), t + 4),  # within the grace: still the run's
        ],
    )
    files.tick(t + LIMITS.late_grace_ns)  # the grace is not over
    assert files.closed_paths == []
    files.tick(t + 3 + LIMITS.late_grace_ns)
    (run1,) = files.closed_paths
    assert run1.name == "st1_run1_221320.mcap" and run1.is_file()
    assert counts(run1) == {"tool": 2, "samples": 1, "runs": 1, "bus": 1}
    later = t + 5 * SECOND_NS
    feed(
        files,
        [
            ("tool", tool(1, "idle", later), later),  # the ended run's id: not a file of its
            ("bus", bus(later + 1), later + 1),
            ("bus", bus(later + SECOND_NS), later + SECOND_NS),
            ("tool", tool(2, "running", later + 2 * SECOND_NS), later + 2 * SECOND_NS),
        ],
    )
    files.tick(later + 10 * SECOND_NS)  # the idle file's grace after run 2's start
    files.close()
    names = [p.name for p in files.closed_paths]
    assert names == ["st1_run1_221320.mcap", "st1_idle_221325.mcap", "st1_run2_221327.mcap"]
    assert counts(files.closed_paths[1]) == {"bus": 2, "tool": 1}
    assert counts(files.closed_paths[2]) == {"tool": 1}
