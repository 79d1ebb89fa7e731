"""``boltwatch serve predictor`` for an edge station is refused at once, in any start order.

On an edge station (``[predictor] placement = "edge"``, the default) the acquisition
decides on its CAN thread. A line predictor for it would race the acquisition for the
station's ``health/predictor`` token (whichever came second would refuse, and a predictor
that won would leave the station without an acquisition), so the predictor refuses from
the file alone: exit status 2, one line, before it opens zenoh, whether the line's router
is up or not, whether the acquisition runs already or starts after it; the acquisition is
never disturbed. Real processes on loopback: a router, the acquisition, the predictor.
"""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from services.cli.station_supervisor import stop_process
from shared.contract import keys
from shared.runtime import open_from, zenoh_config
from tests.support.router_process import boltwatch
from tests.support.station_files import serve, write_station

pytestmark = pytest.mark.system

START_TIMEOUT_S = 30.0


def refusal_line(station_file: Path) -> str:
    return (
        f"boltwatch serve predictor: {station_file}: predictor.placement: 'edge' (the "
        "default): on an edge station the acquisition decides (st1, on its CAN thread), there "
        f"is no predictor to start: start 'boltwatch serve acquisition --config {station_file}' "
        'instead, or set placement = "line" for a predictor over zenoh'
    )


def serve_predictor(station_file: Path) -> subprocess.CompletedProcess[str]:
    return boltwatch("serve", "predictor", "--config", str(station_file), timeout_s=60)


def assert_refused(station_file: Path) -> None:
    done = serve_predictor(station_file)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines() == [refusal_line(station_file)]
    assert done.stdout == ""


def alive(endpoint: str, service: str) -> bool:
    with open_from(zenoh_config("client", [endpoint], connect_timeout_ms=5000)) as session:
        replies = session.liveliness().get(keys.health_key("st1", service), timeout=1.0)
        return any(reply.ok is not None for reply in replies)


@pytest.fixture
def processes(tmp_path: Path) -> Iterator[list[subprocess.Popen[bytes]]]:
    """Started by the test when it wants it; stopped at the end."""
    started: list[subprocess.Popen[bytes]] = []
    yield started
    for process in started:
        stop_process(process, grace_s=10)


def test_the_predictor_of_an_edge_station_refuses_at_once_before_and_after_the_acquisition(
    tmp_path: Path,
    router: str,
    processes: list[subprocess.Popen[bytes]],
) -> None:
    station_file = write_station(tmp_path, zenoh_port=int(router.rsplit(":", 1)[1]))

    assert_refused(station_file)  # the acquisition not started yet

    log = tmp_path / "acquisition.log"
    processes.append(serve(["acquisition", "--config", str(station_file)], log))
    deadline = time.monotonic() + START_TIMEOUT_S
    while not (alive(router, "acquisition") and alive(router, "predictor")):
        assert processes[0].poll() is None, log.read_text()
        assert time.monotonic() < deadline, "the acquisition did not come up"

    assert_refused(station_file)  # the acquisition running: the same line

    assert processes[0].poll() is None, log.read_text()
    assert alive(router, "acquisition") and alive(router, "predictor")


def test_without_a_router_the_refusal_is_the_same_line(tmp_path: Path) -> None:
    """From the file alone: nothing listens on the file's router endpoint."""
    station_file = write_station(tmp_path)
    assert_refused(station_file)


def test_a_line_placed_station_still_gets_its_predictor(
    tmp_path: Path,
    router: str,
    processes: list[subprocess.Popen[bytes]],
) -> None:
    station_file = write_station(
        tmp_path, zenoh_port=int(router.rsplit(":", 1)[1]), placement="line"
    )
    log = tmp_path / "predictor.log"
    processes.append(serve(["predictor", "--config", str(station_file)], log))
    deadline = time.monotonic() + START_TIMEOUT_S
    while not alive(router, "predictor"):
        assert processes[0].poll() is None, log.read_text()
        assert time.monotonic() < deadline, "the line predictor did not come up"
