"""The live predictor against payloads a hostile but fair tester sends: counted, never fatal.

Real zenoh on loopback, the real :class:`PredictorService` (:mod:`.live_predictor`):
after the bad payloads a whole run is still predicted and decided, and what
was refused shows in the station's ``PredictorStats`` on ``boltwatch/<st>/predictor``.
"""

from __future__ import annotations

import time

import pytest
import zenoh

from services.predictor.service import PredictorService
from shared.contract import PredictorStats, RunSummary, StopDecision, codec, keys
from shared.runtime import zenoh_config
from tests.support.factories import sample
from tests.support.live_predictor import (
    PROGRAM_OF,
    START_NS,
    StationFeed,
    collect,
    wait_for_token,
)
from tests.support.synthetic_runs import staircase

DEEP = 100_000  # [[[[...]]]] 100 000 deep (200 kB)
DEEP_WITHIN_SIZE = 30_000  # 60 kB: under the size bound, so the parser itself must cope
HOUR_NS = 3_600_000_000_000


def nested(depth: int) -> bytes:
    return b"[" * depth + b"]" * depth


def play_run(feed: StationFeed, run_id: int, bad_row: int | None = None) -> None:
    """A whole run at pt1; ``bad_row``: that sample is stamped an hour ahead."""
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    feed.state(run_id, PROGRAM_OF["pt1"], "running", START_NS)
    for i, row in enumerate(trace.rows()):
        if i == bad_row:
            t, torque, force, angle = row
            feed.sample(run_id, i, (t + HOUR_NS / 1e9, torque, force, angle))
        else:
            feed.sample(run_id, i, row)
    feed.state(run_id, PROGRAM_OF["pt1"], "done", START_NS + 2_000_000_000, "plateau_closest")


def decided(by_key: dict[str, list[bytes]]) -> tuple[StopDecision, RunSummary]:
    (decision,) = [codec.decode(StopDecision, p) for p in by_key.get("pt1/decision", [])]
    (summary,) = [codec.decode(RunSummary, p) for p in by_key.get("pt1/runs", [])]
    return decision, summary


def latest_stats(by_key: dict[str, list[bytes]]) -> PredictorStats:
    return codec.decode(PredictorStats, by_key["pt1/predictor"][-1])


def test_deep_nesting_and_impossible_times_are_counted_and_the_next_run_is_decided(
    service: PredictorService, endpoint: str
) -> None:
    """Before: a RecursionError out of the decoder ended the predictor (all stations), and
    a run started at time_ns -1 or 10**30 was predicted on that clock."""
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        received = session.declare_subscriber("boltwatch/pt1/*", zenoh.handlers.FifoChannel(10_000))
        feed = StationFeed(session, "pt1")
        for payload in (nested(DEEP), nested(DEEP_WITHIN_SIZE), b'{"a":' * DEEP_WITHIN_SIZE):
            feed.samples.put(payload)
            feed.tool.put(payload)
        for time_ns in (-1, 10**30):  # times no clock can hold: 0 to 2**63 - 1 ns
            feed.state(41, PROGRAM_OF["pt1"], "running", time_ns)
            feed.samples.put(codec.encode(sample(41, 0, station="pt1", time_ns=time_ns)))
        play_run(feed, 42)
        by_key = collect(received, until={"pt1/decision", "pt1/runs"}, timeout_s=30.0)
        deadline = time.monotonic() + 30.0  # the next PredictorStats after the run (a bound)
        while time.monotonic() < deadline and (
            "pt1/predictor" not in by_key or latest_stats(by_key).bad_payloads < 10
        ):
            by_key.update(collect(received, until={"pt1/predictor"}, timeout_s=1.5))
        received.undeclare()
        feed.close()
    decision, summary = decided(by_key)
    assert decision.reason == "plateau_closest"
    assert summary.stop_reason == "plateau_closest" and summary.samples > 900
    assert service.bad_payloads == 10 and service.unfinished_runs == 0  # run 41 never started
    stats = latest_stats(by_key)
    assert (stats.station, stats.bad_payloads, stats.bad_samples) == ("pt1", 10, 0)


def test_a_sample_stamped_an_hour_ahead_is_one_bad_sample_of_the_live_run(
    service: PredictorService, endpoint: str
) -> None:
    """The core takes one sample an hour ahead for one bad timestamp; through the live
    service (run time from the run's ToolState) the run is decided as without it, and
    the bad sample shows in the station's PredictorStats once the run has ended."""
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        received = session.declare_subscriber("boltwatch/pt1/*", zenoh.handlers.FifoChannel(10_000))
        feed = StationFeed(session, "pt1")
        play_run(feed, 42, bad_row=300)
        by_key = collect(received, until={"pt1/decision", "pt1/runs"}, timeout_s=30.0)
        deadline = time.monotonic() + 30.0  # a bound, not a timing
        while time.monotonic() < deadline and (
            "pt1/predictor" not in by_key or latest_stats(by_key).bad_samples < 1
        ):
            by_key.update(collect(received, until={"pt1/predictor"}, timeout_s=1.5))
        received.undeclare()
        feed.close()
    decision, summary = decided(by_key)
    assert decision.reason == "plateau_closest"  # before the core's fix: input_fault at -57 %
    assert decision.force_n == pytest.approx(30_056.0, abs=150.0)  # as without the bad sample
    assert summary.samples == 1000
    stats = latest_stats(by_key)
    assert (stats.bad_samples, stats.bad_payloads) == (1, 0)
