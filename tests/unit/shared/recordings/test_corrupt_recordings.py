"""Damaged recordings, real files: cut at several offsets, garbage in a chunk, a wrong
magic, an empty file. ``boltwatch export``, ``inspect`` and ``recover`` each read what
is readable and say how much was lost, or end with one line naming the file, what is
wrong and where (status 2)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from mcap.reader import make_reader

from services.cli.main import main
from shared.contract import Sample, ToolState, encode, read_trace
from shared.recordings import classify
from shared.recordings.mcap import McapSink, RecordingScan

T0_NS = 1_700_000_000_000_000_000
SAMPLES = 3000
CHUNKS = 6  # one flush per 500 samples


@pytest.fixture
def good(tmp_path: Path) -> Path:
    path = tmp_path / "good.mcap"
    with McapSink(path, {"station": {"station": "st1"}}, 1, T0_NS) as sink:
        state = encode(ToolState("st1", 1, 7, 1, "running", T0_NS))
        sink.write(classify("boltwatch/st1/tool", state, T0_NS))
        for n in range(SAMPLES):
            time_ns = T0_NS + n * 1_000_000
            sample = Sample("st1", 1, n, time_ns, 1.0 + n, 0.1 * n, 2.0 * n)
            sink.write(classify("boltwatch/st1/samples", encode(sample), time_ns))
            if n % 500 == 499:
                sink.flush()
    return path


def chunk_starts(path: Path) -> list[int]:
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    return sorted(index.chunk_start_offset for index in summary.chunk_indexes)


def damaged(good: Path, name: str, data: bytes) -> Path:
    path = good.with_name(name)
    path.write_bytes(data)
    return path


def run_cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    status = main(args)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize("keep_fraction", [0.25, 0.5, 0.75, 0.999])
def test_a_cut_file_exports_inspects_and_recovers_its_readable_part(
    good: Path, keep_fraction: float, capsys: pytest.CaptureFixture[str]
) -> None:
    data = good.read_bytes()
    keep = int(len(data) * keep_fraction)
    cut = damaged(good, "cut.mcap", data[:keep])
    whole_chunks = sum(1 for start in chunk_starts(good) if start < keep) - 1

    status, out, err = run_cli(["export", str(cut)], capsys)
    assert status == 0
    (warning,) = err.splitlines()
    lost = re.search(r"incomplete, read (\d+) of (\d+) bytes, (\d+) bytes lost", warning)
    assert lost is not None and int(lost[2]) == keep, warning
    assert "cut off inside a record after byte" in warning and str(cut) in warning
    rows = len(read_trace(cut.with_suffix(".csv")))
    assert f"wrote {rows} samples" in out
    assert rows >= 500 * min(whole_chunks, CHUNKS)  # every complete chunk is read
    assert read_trace(cut.with_suffix(".csv")).torque_nm[0] == 1.0

    status, out, err = run_cli(["inspect", str(cut), "--out", str(cut.with_suffix(".png"))], capsys)
    assert status == 0 and cut.with_suffix(".png").stat().st_size > 0
    assert "warning:" in err and f"{int(lost[3])} bytes lost" in err
    assert f"{rows} samples" in out

    status, out, err = run_cli(["recover", str(cut)], capsys)
    assert status == 0, err
    recovered = cut.with_name("cut.recovered.mcap")
    with recovered.open("rb") as handle:  # the mcap library's indexed reader: a valid file
        sequences = [
            message.sequence
            for _, channel, message in make_reader(handle).iter_messages()
            if channel.topic.endswith("/samples")
        ]
    assert sequences == list(range(rows))


def test_garbage_in_a_chunk_stops_there_and_says_where(
    good: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    starts = chunk_starts(good)
    third = starts[2]
    data = bytearray(good.read_bytes())
    data[third + 80 : third + 144] = b"\xab" * 64
    broken = damaged(good, "garbage.mcap", bytes(data))

    status, out, err = run_cli(["export", str(broken)], capsys)
    assert status == 0
    where = re.search(r"damaged record after byte (\d+) \((\w+): ", err)
    assert where is not None, err
    assert starts[1] < int(where[1]) <= third  # after the 2nd chunk, at most at the 3rd
    assert where[2] in ("ZstdError", "CRCValidationError") and str(broken) in err
    assert len(read_trace(broken.with_suffix(".csv"))) == 1000  # the two chunks before it
    status, out, _ = run_cli(["recover", str(broken)], capsys)
    assert status == 0 and "recovered 1001 messages" in out


@pytest.mark.parametrize(
    ("name", "make", "expected"),
    [
        ("empty.mcap", lambda data: b"", "no MCAP data (empty file)"),
        (
            "magic.mcap",
            lambda data: b"NOTMCAP0" + data[8:],
            "not an MCAP file (byte 0: b'NOTMCAP0', expected the MCAP magic b'\\x89MCAP0\\r\\n')",
        ),
        ("cut4.mcap", lambda data: data[:4], "cut off after 4 bytes, inside the MCAP magic"),
        ("cut20.mcap", lambda data: data[:20], "the MCAP header at byte 8 is unreadable"),
    ],
)
def test_an_unreadable_file_is_one_line_and_status_2(
    good: Path,
    name: str,
    make: object,
    expected: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert callable(make)
    path = damaged(good, name, make(good.read_bytes()))
    for command in ("export", "inspect", "recover"):
        status, out, err = run_cli([command, str(path)], capsys)
        assert status == 2 and out == ""
        (line,) = err.splitlines()
        assert line.startswith(f"boltwatch {command}: {path}: {expected}"), line
    assert not path.with_name(f"{path.stem}.recovered.mcap").exists()


def test_an_intact_file_reads_as_complete(good: Path) -> None:
    scan = RecordingScan(good)
    assert sum(1 for _ in scan.messages("/samples")) == SAMPLES
    assert scan.complete and scan.describe() == f"{good}: complete"
