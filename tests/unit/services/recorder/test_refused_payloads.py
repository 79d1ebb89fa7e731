"""The live recorder against payloads no recording should hold as they are: raw, counted, alive.

A real :class:`RecorderService` in a thread (conftest), fed over real zenoh
on loopback; what it wrote is read back from its MCAP file. A message whose
time no MCAP timestamp can hold (-1, 10**30), one nested 100 000 deep, one
stamped an hour ahead of its arrival: each is recorded byte for byte on its
key's raw channel with its arrival as publish time, counted in
``RecorderStats.bad_payloads``, logged once, and the recorder goes on.
"""

from __future__ import annotations

import json
import threading
import time
from typing import Any

import pytest
import zenoh
from mcap.reader import make_reader

from shared.config import LoadedStation
from shared.contract import Sample, StopDecision, ToolState, channels, encode, keys
from shared.recordings.mcap import RAW_ENCODING
from tests.support.factories import sample, summary
from tests.support.live_recorder import RunningRecorder, publish, wait_until
from tests.support.recorded_runs import recorded_files

RUN = 7
HOUR_NS = 3_600_000_000_000
MS_NS = 1_000_000


def live_run(t0_ns: int, samples: int) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
    """(the run's first half, the rest), stamped from ``t0_ns``: now, as a live station."""
    start = [("tool", ToolState("st1", RUN, 7, 1, "running", t0_ns))]
    rows = [
        ("samples", Sample("st1", RUN, n, t0_ns + n * MS_NS, 1.0 + n, 0.1 * n, 10_000.0 + n))
        for n in range(samples)
    ]
    end_ns = t0_ns + samples * MS_NS
    run = summary(
        RUN,
        events=0,
        stop_reason=None,
        process_intensity=1.5,
        samples=samples,
        started_ns=t0_ns,
        ended_ns=end_ns,
    )
    rest = [("tool", ToolState("st1", RUN, 7, 1, "done", end_ns)), ("runs", run)]
    half = samples // 2
    return start + rows[:half], rows[half:] + rest


def hostile(t0_ns: int) -> list[tuple[str, bytes]]:
    """The probes, each a payload that must not reach a typed channel as it is."""
    ahead = sample(RUN, 9999, time_ns=t0_ns)
    decision = StopDecision("st1", RUN, t0_ns, 0.1, "plateau_closest", "", 1.0, None, None, t0_ns)
    return [
        ("tool", encode(ToolState("st1", RUN, 7, 1, "running", -1))),
        ("tool", encode(ToolState("st1", RUN, 7, 1, "running", 10**30))),
        ("samples", encode(sample(RUN, 9999, time_ns=-1))),
        ("samples", encode(sample(RUN, 9999, time_ns=10**30))),
        (
            "decision",
            encode(
                StopDecision("st1", RUN, 10**30, 0.1, "plateau_closest", "", 1.0, None, None, t0_ns)
            ),
        ),
        ("samples", b"[" * 100_000 + b"]" * 100_000),
        ("samples", b"[" * 30_000 + b"]" * 30_000),  # within the size bound: the parser copes
        ("runs", b'{"a":' * 10_000),
        (
            "samples",
            json.dumps({**json.loads(encode(ahead)), "time_ns": t0_ns + HOUR_NS}).encode(),
        ),
        ("decision", encode(decision).replace(b'"time_ns":', b'"time_ns":1', 1)),  # ~years ahead
    ]


def test_times_no_recording_can_hold_and_deep_nesting_are_recorded_raw_and_counted(
    station: LoadedStation,
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
    caplog: pytest.LogCaptureFixture,
) -> None:
    """Before: the first ``time_ns`` -1 or 10**30 killed the recorder (struct.error in the
    MCAP writer), and deep nesting with a RecursionError."""
    stats: list[dict[str, Any]] = []
    lock = threading.Lock()

    def heard(sample: zenoh.Sample) -> None:
        with lock:
            stats.append(json.loads(sample.payload.to_bytes()))

    watcher = publisher_session.declare_subscriber(channels.RECORDER.key("st1"), heard)
    t0_ns = time.time_ns()
    first, rest = live_run(t0_ns, 200)
    bad = hostile(t0_ns)
    sent = publish(publisher_session, first + bad + rest)
    wait_until(lambda: recorder.service.recorder.messages == sent, "every message recorded")
    assert recorder.thread.is_alive()

    def counted() -> bool:
        with lock:
            return any(s.get("bad_payloads") == len(bad) for s in stats)

    wait_until(counted, "RecorderStats counting the refused payloads")
    watcher.undeclare()
    recorder.finish()

    (path,) = recorded_files(station)  # one file: no rotation, no run started by a bad state
    assert f"_run{RUN}_" in path.name
    typed: dict[str, list[Any]] = {}
    raw: list[tuple[str, bytes, int, int]] = []
    with path.open("rb") as handle:
        for _, channel, message in make_reader(handle).iter_messages(log_time_order=False):
            if channel.message_encoding == RAW_ENCODING:
                raw.append((channel.topic, message.data, message.log_time, message.publish_time))
            else:
                typed.setdefault(channel.topic, []).append(json.loads(message.data))
    assert [(topic, data) for topic, data, _, _ in raw] == [
        (keys.station_key("st1", topic), payload) for topic, payload in bad
    ]
    assert all(publish_ns == log_ns for _, _, log_ns, publish_ns in raw)
    assert [s["sequence"] for s in typed["boltwatch/st1/samples"]] == list(range(200))
    assert [s["state"] for s in typed["boltwatch/st1/tool"]] == ["running", "done"]
    assert "boltwatch/st1/decision" not in typed
    with lock:
        lags = [s["lag_max_ms"] for s in stats if s["lag_max_ms"] is not None]
    assert lags and max(lags) < 60_000  # no refused sample's time in the lag figures
    refused_lines = [r for r in caplog.records if r.getMessage().startswith("payload on")]
    assert len(refused_lines) == 1 and not any(r.exc_info for r in caplog.records)


def test_a_wear_query_the_recorder_cannot_answer_ends_at_once(
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
    caplog: pytest.LogCaptureFixture,
) -> None:
    """No ledger yet: one error reply, and the query ends with it. Before: the Query stayed
    alive through the logged error's traceback (a log record keeps it), so zenoh finished
    it only at the querier's timeout, with a second, "Timeout" reply."""
    key = keys.station_key("st1", keys.WEAR)
    for selector, payload in ((key, None), (f"{key}?x=1;;&\u00fe", b"\x00" * 5000)):
        started = time.monotonic()
        replies = list(publisher_session.get(selector, payload=payload, timeout=10.0))
        took_s = time.monotonic() - started
        assert [r.err is not None for r in replies] == [True]
        assert b"no wear ledger" in replies[0].err.payload.to_bytes()  # type: ignore[union-attr]
        assert took_s < 5.0
    assert caplog.records  # the error was logged, and the log kept it
