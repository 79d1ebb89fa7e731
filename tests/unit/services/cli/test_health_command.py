"""``boltwatch health SERVICE``: over a real zenoh session holding the services' tokens."""

from __future__ import annotations

from pathlib import Path

import pytest
import zenoh

from services.cli.main import main
from shared.contract import keys
from shared.runtime import zenoh_config
from tests.support.live_recorder import free_port

CONTROLLER_STATION = Path(__file__).parents[4] / "config" / "controller-station.toml"


def controller_station(folder: Path, endpoint: str) -> Path:
    """The shipped controller station file (station op1) as a client of ``endpoint``."""
    text = CONTROLLER_STATION.read_text(encoding="utf-8")
    text = text.replace('connect = ["tcp/127.0.0.1:7447"]', f'connect = ["{endpoint}"]')
    text = text.replace('folder = "../recordings"', f'folder = "{folder / "recordings"}"')
    path = folder / "op1.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_health_knows_the_open_protocol_bridge(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A controller station's container checks its bridge. Before: ``openprotocol`` was no
    choice (exit 2, "invalid choice")."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    station = controller_station(tmp_path, endpoint)
    with zenoh.open(zenoh_config("peer", listen=[endpoint])) as line:
        assert main(["health", "openprotocol", "--config", str(station)]) == 1
        assert capsys.readouterr().err.strip() == "openprotocol: not alive for op1"
        token = line.liveliness().declare_token(keys.health_key("op1", "openprotocol"))
        assert main(["health", "openprotocol", "--config", str(station)]) == 0
        assert capsys.readouterr().out.strip() == "openprotocol: alive for op1"
        token.undeclare()
