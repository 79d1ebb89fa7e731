"""``serve rig --controller openprotocol``: refusals in one line, the tightening counter kept
across restarts."""

from __future__ import annotations

from pathlib import Path

from services.rig.openprotocol.tightening_counter import TighteningCounter
from tests.support.paths import STATION_FILE
from tests.support.router_process import boltwatch


def test_a_station_without_the_section_is_refused_in_one_line() -> None:
    result = boltwatch(
        "serve", "rig", "--controller", "openprotocol", "--config", str(STATION_FILE), timeout_s=60
    )
    assert result.returncode == 2, result.stderr
    lines = [line for line in result.stderr.splitlines() if "openprotocol" in line]
    assert len(lines) == 1 and "the section is needed by --controller openprotocol" in lines[0]
    assert "Traceback" not in result.stderr


def test_the_tightening_counter_is_kept_and_an_unreadable_one_starts_again(
    tmp_path: Path,
) -> None:
    counter = TighteningCounter.of_station(tmp_path / "recordings", "st1")
    assert counter.last() == 0
    counter.keep(41)
    counter.keep(42)
    assert TighteningCounter.of_station(tmp_path / "recordings", "st1").last() == 42
    counter.path.write_text("{not json")
    assert counter.last() == 0
