"""The loading OPC UA clients of ``bench_opcua_publish.py``: node-opcua processes
(``opcua_publish_client.js``) and what each heard.

Each client subscribes to the result-ready events of every station and asks
each result's trace by ``GetResultById``, one call at a time, oldest first; it
prints a JSON line per event and per answer, with ``CLOCK_MONOTONIC`` times
(Python's ``time.monotonic_ns``), which a thread of this process reads into
:class:`LoadClient`. :func:`step_figures` turns what the clients heard of a
step's results into its figures.
"""

from __future__ import annotations

import json
import os
import subprocess
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.support.opcua_certificates import OpcuaCertificates, client_uri

SCRIPT = Path(__file__).with_name("opcua_publish_client.js")
SUBSCRIBE_TIMEOUT_S = 180.0  # the server loads its models first (10 s and more, loaded)


def percentile(values: Sequence[float], share: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))]


@dataclass(frozen=True)
class Answer:
    result_id: str
    sent_ns: int
    answered_ns: int
    error: int
    points: int  # the trace's samples (0: no trace)


class LoadClient:
    """One client process; its events (ResultId -> receipt ns) and answers, as they come."""

    def __init__(
        self,
        modules: Path,
        name: str,
        endpoint: str,
        certificates: OpcuaCertificates,
        stations: Sequence[str],
        security: str,
        user: tuple[str, str],
        publishing_interval_ms: float,
        log: Path,
    ) -> None:
        certificate, key = certificates.clients[name]
        options = {
            "endpoint": endpoint,
            "certificate": str(certificate),
            "privateKey": str(key),
            "applicationUri": client_uri(name),
            "security": security,
            "stations": list(stations),
            "userName": user[0],
            "password": user[1],
            "publishingIntervalMs": publishing_interval_ms,
        }
        self.name = name
        self._log = log.open("w")
        self.process = subprocess.Popen(
            ["node", str(SCRIPT), json.dumps(options)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._log,
            text=True,
            env={**os.environ, "NODE_PATH": str(modules)},
        )
        self.events: dict[str, int] = {}
        self.answers: list[Answer] = []
        self.publishing_interval_ms: float | None = None
        self.errors: list[str] = []
        self._subscribed = threading.Event()
        self._skipped = threading.Event()
        self._lock = threading.Lock()
        self._reader = threading.Thread(target=self._read, name=f"{name}-out", daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            if not line.startswith('{"t"'):  # node-opcua's own warnings
                continue
            heard = json.loads(line)
            kind = heard["t"]
            with self._lock:
                if kind == "e":
                    self.events.setdefault(heard["id"], int(heard["ns"]))
                elif kind == "r":
                    self.answers.append(
                        Answer(
                            heard["id"],
                            int(heard["sent"]),
                            int(heard["ns"]),
                            heard["error"],
                            heard["points"],
                        )
                    )
                elif kind == "subscribed":
                    self.publishing_interval_ms = heard["publishingIntervalMs"]
                    self._subscribed.set()
                elif kind == "skipped":
                    self._skipped.set()
                elif kind == "error":
                    self.errors.append(heard["message"])
        self._subscribed.set()  # ended: nobody waits for it any longer
        self._skipped.set()

    def wait_subscribed(self) -> None:
        if not self._subscribed.wait(SUBSCRIBE_TIMEOUT_S) or self.process.poll() is not None:
            raise SystemExit(f"client {self.name} did not subscribe: {self.errors}")

    def received(self, ids: Sequence[str]) -> int:
        """How many of ``ids`` it received the event of."""
        with self._lock:
            return sum(1 for result_id in ids if result_id in self.events)

    def answered(self, ids: set[str]) -> int:
        with self._lock:
            return sum(1 for answer in self.answers if answer.result_id in ids)

    def skip(self) -> None:
        """Drop the results not yet asked (the call under way is answered)."""
        self._skipped.clear()
        self._send("skip")
        self._skipped.wait(30.0)

    def _send(self, line: str) -> None:
        if self.process.poll() is None and self.process.stdin is not None:
            self.process.stdin.write(line + "\n")
            self.process.stdin.flush()

    def stop(self) -> None:
        self._send("stop")
        try:
            self.process.wait(timeout=15.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._reader.join(5.0)
        self._log.close()

    def snapshot(self) -> tuple[dict[str, int], list[Answer]]:
        with self._lock:
            return dict(self.events), list(self.answers)


def wait_delivered(clients: Sequence[LoadClient], ids: Sequence[str], limit_s: float) -> bool:
    """Until every client received every one of ``ids`` (False: ``limit_s`` ran out)."""
    deadline = time.monotonic() + limit_s
    while any(client.received(ids) < len(ids) for client in clients):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def wait_answered(clients: Sequence[LoadClient], ids: Sequence[str], until: float) -> None:
    """Until every client has the answer of every one of ``ids`` or ``until`` (monotonic s)."""
    wanted = set(ids)
    while any(client.answered(wanted) < len(wanted) for client in clients):
        if time.monotonic() > until:
            return
        time.sleep(0.05)


@dataclass(frozen=True)
class StepFigures:
    """What the clients heard of a step's results."""

    results: int
    delivered_to_all: int  # results whose event every client received
    delivered_s: float | None  # first put to the last receipt of them all (None: not all)
    event_ms: tuple[float, float]  # put -> receipt, p50 and p99, every client's
    traces: int  # GetResultById answered, every client's
    traces_with_samples: int
    trace_ms: tuple[float, float]  # a call, p50 and p99
    errors: int  # answers with Error != 0

    def line(self, seconds_s: float) -> str:
        sustained = (
            f"{self.results / self.delivered_s:.0f}/s" if self.delivered_s else "not all delivered"
        )
        return (
            f"events to all clients {self.delivered_to_all}/{self.results} ({sustained}), "
            f"latency p50 {self.event_ms[0]:.1f} ms p99 {self.event_ms[1]:.1f} ms; traces "
            f"answered {self.traces} ({self.traces / seconds_s:.1f}/s, {self.traces_with_samples}"
            f" with samples, {self.errors} errors), a call p50 {self.trace_ms[0]:.0f} ms "
            f"p99 {self.trace_ms[1]:.0f} ms"
        )


def step_figures(clients: Sequence[LoadClient], put_ns: dict[str, int]) -> StepFigures:
    """The figures of the results put at ``put_ns`` (ResultId -> monotonic ns)."""
    latencies: list[float] = []
    calls: list[float] = []
    last_ns: dict[str, int] = {}
    everyone = dict.fromkeys(put_ns, 0)
    traces = with_samples = errors = 0
    for client in clients:
        events, answers = client.snapshot()
        for result_id, sent_ns in put_ns.items():
            received_ns = events.get(result_id)
            if received_ns is None:
                continue
            everyone[result_id] += 1
            latencies.append((received_ns - sent_ns) / 1e6)
            last_ns[result_id] = max(last_ns.get(result_id, 0), received_ns)
        for answer in answers:
            if answer.result_id in put_ns:
                traces += 1
                with_samples += answer.points > 0
                errors += answer.error != 0
                calls.append((answer.answered_ns - answer.sent_ns) / 1e6)
    delivered = [result_id for result_id, count in everyone.items() if count == len(clients)]
    delivered_s = None
    if len(delivered) == len(put_ns) and put_ns:
        delivered_s = (max(last_ns.values()) - min(put_ns.values())) / 1e9
    return StepFigures(
        len(put_ns),
        len(delivered),
        delivered_s,
        (percentile(latencies, 0.5), percentile(latencies, 0.99)),
        traces,
        with_samples,
        (percentile(calls, 0.5), percentile(calls, 0.99)),
        errors,
    )


def figures_json(figures: StepFigures) -> dict[str, Any]:
    return {
        "results": figures.results,
        "delivered_to_all": figures.delivered_to_all,
        "delivered_per_s": round(figures.results / figures.delivered_s, 1)
        if figures.delivered_s
        else None,
        "event_ms_p50_p99": [round(v, 1) for v in figures.event_ms],
        "traces": figures.traces,
        "traces_with_samples": figures.traces_with_samples,
        "trace_ms_p50_p99": [round(v) for v in figures.trace_ms],
        "errors": figures.errors,
    }
