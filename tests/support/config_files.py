"""Station files a test writes from the shipped one."""

from __future__ import annotations

from pathlib import Path

from tests.support.paths import CONFIG, STATION_FILE

STATION_TEXT = STATION_FILE.read_text()


def write_station(tmp_path: Path, text: str) -> Path:
    """A copy of the shipped station file with absolute paths, edited by ``text`` replacements."""
    body = STATION_TEXT.replace('"joints/', f'"{CONFIG}/joints/').replace(
        '"can/', f'"{CONFIG}/can/'
    )
    path = tmp_path / "station.toml"
    path.write_text(body + text)
    return path
