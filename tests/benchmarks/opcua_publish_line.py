"""The line of ``bench_opcua_publish.py``: its processes, its recordings and the results put.

:class:`Line`: a router and ``serve recorder`` (MCAP only) for the stations' files,
and, when asked, ``serve opcua`` (Basic256Sha256 sign and encrypt, the clients' CA
trusted, a users file: the clients log in) with its node-opcua clients
(:mod:`.opcua_publish_clients`), warmed up before it is measured. :func:`recorded`:
each station's runs recorded by the real recorder (:mod:`.run_recordings`) and
stored by ``results rebuild``, so each result served has its real trace.
:class:`Results`: those results put on ``boltwatch/<st>/results`` at a rate, each
once, with the time of each put.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import subprocess
import sys
import time
from pathlib import Path

import zenoh

from services.cli.station_supervisor import stop_process
from services.opcua.password_hashes import hash_password
from services.opcua.result_values import result_id
from services.opcua.users_file import OpcuaUser, write_users
from shared.config import load_station
from shared.contract import TighteningResult, channels, encode
from shared.results import ResultsQuery, ResultsStore, StoreError, station_store
from tests.benchmarks.bench_line import wait_alive
from tests.benchmarks.opcua_publish_clients import (
    LoadClient,
    step_figures,
    wait_delivered,
)
from tests.benchmarks.run_recordings import record_runs
from tests.support.opcua_certificates import make_opcua_certificates
from tests.support.opcua_client import node_opcua_client
from tests.support.paths import REPO
from tests.support.station_files import free_tcp_port, serve

RUN_SPACING_NS = 30 * 1_000_000_000  # record_runs: a run every 30 s or so
STORE_TIMEOUT_S = 60.0  # the results store there once the recorder started
PROFILED_SERVER = Path(__file__).with_name("opcua_profiled_server.py")
#: the clients' user in the server's users file
USER, PASSWORD = "line-mes", "the benchmark's password"
WARM_UP_S = 60.0
WARM_MS = 500.0
WARM_IN_A_ROW = 3


class Line:
    """The router, the recorder and (when started) the OPC UA server with its clients."""

    def __init__(
        self, args: argparse.Namespace, folder: Path, files: list[Path], endpoint: str
    ) -> None:
        self.args = args
        self.folder = folder
        self.files = [str(path) for path in files]
        self.stations = [path.stem for path in files]
        self.endpoint = endpoint
        self.certificates = make_opcua_certificates(
            folder / "pki", clients=tuple(f"client{n}" for n in range(1, args.clients + 1))
        )
        self.users = folder / "opcua-users.toml"
        write_users(self.users, {USER: OpcuaUser(USER, hash_password(PASSWORD))})
        self.processes: list[subprocess.Popen[bytes]] = []
        self.server: subprocess.Popen[bytes] | None = None
        self.clients: list[LoadClient] = []
        self.opcua_endpoint = ""

    def start(self) -> None:
        self.processes.append(
            serve(["router", "--listen", self.endpoint], self.folder / "router.log")
        )
        self.recorder = serve(
            ["recorder", "--config", *self.files, "--no-rerun"], self.folder / "recorder.log"
        )
        self.processes.append(self.recorder)

    def start_server(
        self, session: zenoh.Session, results: Results, profile: Path | None = None
    ) -> None:
        modules, reason = node_opcua_client()
        if modules is None:
            raise SystemExit(reason)
        self.opcua_endpoint = f"opc.tcp://127.0.0.1:{free_tcp_port()}"
        certificates = self.certificates
        arguments = [
            *("opcua", "--config", *self.files, "--listen", self.opcua_endpoint),
            *("--certificate", str(certificates.server_certificate)),
            *("--private-key", str(certificates.server_key)),
            *("--trusted-clients", str(certificates.trusted_clients)),
            *("--users", str(self.users)),
        ]
        log = self.folder / "opcua.log"
        if profile is None:
            self.server = serve(arguments, log)
        else:
            with log.open("ab") as out:
                self.server = subprocess.Popen(
                    [sys.executable, str(PROFILED_SERVER), str(profile), *arguments],
                    cwd=REPO,
                    stdout=out,
                    stderr=subprocess.STDOUT,
                )
        wait_alive(session, {(s, "opcua") for s in self.stations}, [self.server], self.folder)
        self.clients = [
            LoadClient(
                modules,
                name,
                self.opcua_endpoint,
                certificates,
                self.stations,
                "SignAndEncrypt",
                (USER, PASSWORD),
                self.args.publishing_interval_ms,
                self.folder / f"{name}.log",
            )
            for name in certificates.clients
        ]
        for client in self.clients:
            client.wait_subscribed()
        self.warm_up(results)

    def warm_up(self, results: Results) -> None:
        """Results put one at a time until :data:`WARM_IN_A_ROW` in a row reach every client
        within :data:`WARM_MS` (the first after subscribing take seconds: the server and the
        clients' publish requests settle), at most :data:`WARM_UP_S`."""
        deadline = time.monotonic() + WARM_UP_S
        in_a_row = warm = 0
        while in_a_row < WARM_IN_A_ROW and time.monotonic() < deadline:
            put_ns = results.put(1.0, 1.0)
            wait_delivered(self.clients, list(put_ns), self.args.drain_s)
            figures = step_figures(self.clients, put_ns)
            in_a_row = in_a_row + 1 if figures.event_ms[1] <= WARM_MS else 0
            warm += 1
            for client in self.clients:
                client.skip()
            time.sleep(0.5)
        print(f"warmed up with {warm} results ({in_a_row} in a row within {WARM_MS} ms)")

    def stop_server(self) -> None:
        for client in self.clients:
            client.stop()
        self.clients = []
        if self.server is not None:
            stop_process(self.server, grace_s=15.0)
            self.server = None

    def close(self) -> None:
        self.stop_server()
        for process in reversed(self.processes):
            stop_process(process, grace_s=15.0)


def recorded(args: argparse.Namespace, folder: Path, files: list[Path], runs: int) -> None:
    """Each station's ``runs`` runs in the recordings folder (kept from an earlier session
    with ``--folder`` when it holds what is asked)."""
    marker = folder / "recorded.json"
    wanted = {"stations": len(files), "runs": runs, "samples": args.samples}
    if marker.is_file() and json.loads(marker.read_text()) == wanted:
        print(f"reusing the recordings of {folder}", flush=True)
        return
    started = time.monotonic()
    start_ns = time.time_ns() - (runs + 10) * RUN_SPACING_NS  # recent: kept by retention
    for path in files:
        record_runs(folder, runs, args.samples, station_file=path, start_ns=start_ns)
    # into the store as ``results rebuild`` reads them (the recorder's catch-up at start
    # reads only the files of the last minutes)
    rebuild = [sys.executable, "-m", "services.cli", "results", "rebuild", "--config"]
    subprocess.run([*rebuild, *map(str, files)], cwd=REPO, check=True, capture_output=True)
    marker.write_text(json.dumps(wanted))
    print(
        f"recorded {runs} runs of {len(files)} stations ({args.samples} samples a run) and "
        f"stored their results in {time.monotonic() - started:.0f} s",
        flush=True,
    )


def stored_results(files: list[Path], expected: int) -> dict[str, list[TighteningResult]]:
    """Each station's results in the store, oldest first (all ``expected`` of them)."""
    target = station_store(load_station(files[0]))
    deadline = time.monotonic() + STORE_TIMEOUT_S
    while True:
        with contextlib.suppress(StoreError), ResultsStore(target, create=False) as store:
            if store.count(ResultsQuery()) >= expected:
                return {
                    path.stem: [
                        found.result
                        for found in store.find(
                            ResultsQuery(stations=[path.stem], oldest_first=True, limit=None)
                        )
                    ]
                    for path in files
                }
        if time.monotonic() > deadline:
            raise SystemExit(f"the recorder's store lacks results after {STORE_TIMEOUT_S} s")
        time.sleep(0.5)


class Results:
    """The stations' recorded results, put on zenoh in turn (each once), and when."""

    def __init__(self, session: zenoh.Session, results: dict[str, list[TighteningResult]]):
        self._publishers = {
            station: session.declare_publisher(
                channels.RESULTS.key(station), congestion_control=zenoh.CongestionControl.BLOCK
            )
            for station in results
        }
        self._left = {station: list(found) for station, found in results.items()}
        self._turn = 0

    def put(self, rate: float, seconds: float) -> dict[str, int]:
        """``rate`` results a second for ``seconds``; ResultId -> when put (monotonic ns)."""
        put_ns: dict[str, int] = {}
        stations = list(self._left)
        started = time.monotonic()
        for n in range(max(1, round(rate * seconds))):
            if (wait := started + n / rate - time.monotonic()) > 0:
                time.sleep(wait)
            station = stations[self._turn % len(stations)]
            self._turn += 1
            result = self._left[station].pop(0)
            put_ns[result_id(station, result.run_id)] = time.monotonic_ns()
            self._publishers[station].put(encode(result))
        return put_ns

    def close(self) -> None:
        for publisher in self._publishers.values():
            publisher.undeclare()
