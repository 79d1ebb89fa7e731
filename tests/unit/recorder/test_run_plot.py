"""``boltwatch inspect`` draws a recorded run into a PNG."""

from __future__ import annotations

from pathlib import Path

import pytest

from services.cli.main import main
from services.recorder.incoming import classify
from services.recorder.mcap_sink import McapSink
from shared.codec import encode
from shared.messages import Sample, StickSlipEvent, StopDecision

T0_NS = 1_700_000_000_000_000_000
MS_NS = 1_000_000


def test_inspect_writes_a_png(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with McapSink(tmp_path / "run1.mcap", {}, 1, T0_NS) as sink:
        for n in range(200):
            sample = Sample("st1", 1, n, T0_NS + n * MS_NS, n % 50 * 1.0, n * 0.1, 1e4 + n * 10)
            sink.write(classify("boltwatch/st1/samples", encode(sample), T0_NS + n * MS_NS))
        for j, n in enumerate((49, 99, 149), start=1):
            event = StickSlipEvent(
                "st1", 1, j, T0_NS + n * MS_NS, n / 1e3, 49.0, 0.0, 49.0, 1e4 + n * 10,
                500.0, 0.05, 20.0, None, None, None, 0.1, 0.1 * j,
            )  # fmt: skip
            sink.write(classify("boltwatch/st1/events", encode(event), T0_NS + n * MS_NS))
        decision = StopDecision(
            "st1", 1, T0_NS + 190 * MS_NS, 0.19, "plateau_closest", "", 40.0, 1.2e4, None, 0
        )
        sink.write(classify("boltwatch/st1/decision", encode(decision), T0_NS + 190 * MS_NS))
    assert main(["inspect", str(sink.path)]) == 0
    png = tmp_path / "run1.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "200 samples, 3 stick-slip events" in capsys.readouterr().out
