"""``serve rig --controller openprotocol``: refusals in one line, the tightening counter kept
across restarts."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from services.rig.openprotocol.tightening_counter import TighteningCounter
from tests.support.paths import REPO, STATION_FILE


def test_a_station_without_the_section_is_refused_in_one_line() -> None:
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "services.cli",
            "serve",
            "rig",
            "--controller",
            "openprotocol",
            "--config",
            str(STATION_FILE),
        ],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=REPO,
        check=False,
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
