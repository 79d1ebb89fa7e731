"""One recorder per station: a second ``serve recorder`` refuses at start, in one line naming
the first, whether it would share the first's recordings folder (its lock) or record the
same station into a folder of its own (the station's liveliness token on the line). A
first recorder that went silent (its host lost power: here it is stopped with SIGSTOP, so
its session's lease runs out) is waited for, at most zenoh's lease, and the second starts.

Real processes: the first recorder runs until the end of the test; each second one is
started, must exit with status 2 and one line, and must leave nothing in a folder.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from shared.contract import keys
from shared.runtime import zenoh_config
from tests.support.live_recorder import free_port, wait_until, write_station_file
from tests.support.paths import REPO
from tests.support.router_process import router_process

pytestmark = pytest.mark.system

SECOND_TIMEOUT_S = 30


def serve_recorder(station_file: Path, *options: str) -> list[str]:
    return [
        sys.executable,
        "-m",
        "services.cli",
        "serve",
        "recorder",
        "--config",
        str(station_file),
        *options,
    ]


@pytest.fixture
def first(tmp_path: Path) -> Iterator[tuple[str, Path, subprocess.Popen[bytes]]]:
    """A recorder of st1 into ``tmp_path/recordings``, alive (its token on the line)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    station_file = write_station_file(
        tmp_path / "first.toml", tmp_path / "recordings", listen=[endpoint]
    )
    with (tmp_path / "first.log").open("w") as log:
        process = subprocess.Popen(
            serve_recorder(station_file, "--no-rerun"),
            cwd=REPO,
            stdout=log,
            stderr=subprocess.STDOUT,
        )
    try:
        with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:

            def alive() -> bool:
                replies = session.liveliness().get(keys.health_key("st1", "recorder"), timeout=1)
                return any(reply.ok is not None for reply in replies)

            wait_until(alive, "the first recorder's token")
        yield endpoint, station_file, process
    finally:
        process.kill()
        process.wait(10)


def refused(command: list[str]) -> str:
    """Run a second recorder: it must end at once with status 2; its one line."""
    result = subprocess.run(
        command, cwd=REPO, capture_output=True, text=True, timeout=SECOND_TIMEOUT_S, check=False
    )
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr
    (line,) = [
        line for line in result.stderr.splitlines() if "ERROR" in line or "boltwatch" in line
    ]
    assert line.startswith("boltwatch serve recorder: "), result.stderr
    return line


def test_a_second_recorder_of_the_same_folder_is_refused_naming_the_first(
    first: tuple[str, Path, subprocess.Popen[bytes]],
) -> None:
    _, station_file, process = first
    line = refused(serve_recorder(station_file, "--no-rerun"))
    assert f"pid {process.pid} on " in line and "held by another recorder" in line
    assert process.poll() is None  # the first records on


def test_a_second_recorder_of_the_station_elsewhere_is_refused_by_its_token(
    first: tuple[str, Path, subprocess.Popen[bytes]], tmp_path: Path
) -> None:
    endpoint, _, process = first
    elsewhere = tmp_path / "elsewhere"
    station_file = write_station_file(tmp_path / "second.toml", elsewhere, connect=[endpoint])
    line = refused(serve_recorder(station_file, "--no-rerun"))
    assert "boltwatch/st1/health/recorder is alive" in line
    assert not list(elsewhere.rglob("*.mcap*"))  # it opened no file
    assert process.poll() is None


def token_alive(session: zenoh.Session) -> bool:
    replies = session.liveliness().get(keys.health_key("st1", "recorder"), timeout=1)
    return any(reply.ok is not None for reply in replies)


def test_a_recorder_whose_host_lost_power_is_waited_for_and_the_next_one_starts(
    tmp_path: Path,
) -> None:
    """The first recorder stopped dead (SIGSTOP: its session says nothing, as after a power
    loss) still holds the station's token on the router until its lease (3 s here) ends;
    the second says so in one line, with the time left, waits, and starts."""
    lease = {"mode": "client", "lease_s": 3}
    with router_process(tmp_path) as endpoint:
        first_file = write_station_file(
            tmp_path / "first.toml", tmp_path / "first", connect=[endpoint], zenoh=lease
        )
        second_file = write_station_file(
            tmp_path / "second.toml", tmp_path / "second", connect=[endpoint], zenoh=lease
        )
        processes: list[subprocess.Popen[bytes]] = []
        try:
            with zenoh.open(zenoh_config("client", [endpoint])) as session:
                with (tmp_path / "first.log").open("w") as log:
                    first = subprocess.Popen(
                        serve_recorder(first_file, "--no-rerun"), cwd=REPO, stdout=log,
                        stderr=subprocess.STDOUT,
                    )  # fmt: skip
                processes.append(first)
                wait_until(lambda: token_alive(session), "the first recorder's token")
                os.kill(first.pid, signal.SIGSTOP)  # as dead as a host without power
                with (tmp_path / "second.log").open("w") as log:
                    second = subprocess.Popen(
                        serve_recorder(second_file, "--no-rerun"), cwd=REPO, stdout=log,
                        stderr=subprocess.STDOUT,
                    )  # fmt: skip
                processes.append(second)

                def second_started_or_ended() -> bool:
                    said = (tmp_path / "second.log").read_text()
                    return "the hold on station(s) st1 ended" in said or second.poll() is not None

                wait_until(second_started_or_ended, "the second recorder", SECOND_TIMEOUT_S)
                assert second.poll() is None, (tmp_path / "second.log").read_text()
                wait_until(lambda: token_alive(session), "the second recorder's token")
        finally:
            for process in processes:
                process.kill()
                process.wait(10)
    (waiting,) = [
        line for line in (tmp_path / "second.log").read_text().splitlines() if "WARNING" in line
    ]
    assert "held by a recorder on the line since" in waiting
    assert "its hold ends within" in waiting and "[zenoh] lease_s = 3 s" in waiting
