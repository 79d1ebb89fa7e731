"""The predictor service on real zenoh: samples and tool states in, messages out.

One service serves two stations (pt1: program 1; pt2: only program 2, so a
pt2 run predicted with pt1's configuration would not be predicted at all);
pt3 is on the same zenoh network but not served (:mod:`.live_predictor`).
"""

from __future__ import annotations

import pytest
import zenoh

from services.predictor.service import PredictorService
from shared.config import LoadedStation
from shared.contract import (
    Intensity,
    RunSummary,
    StickSlipEvent,
    StopDecision,
    TighteningResult,
    channels,
    codec,
    keys,
)
from shared.errors import ConfigError
from shared.runtime import ServiceSkeleton, zenoh_config
from tests.support.factories import sample
from tests.support.live_predictor import (
    PROGRAM_OF,
    START_NS,
    StationFeed,
    collect,
    wait_for_token,
)
from tests.support.live_recorder import wait_until
from tests.support.synthetic_runs import SyntheticTrace, staircase


def check_run(
    by_key: dict[str, list[bytes]], station: str, trace: SyntheticTrace, acted: bool = True
) -> None:
    """``acted``: the acquisition reported that its StopCommand went out for the run."""
    events = [codec.decode(StickSlipEvent, p) for p in by_key.get(f"{station}/events", [])]
    intensities = [codec.decode(Intensity, p) for p in by_key.get(f"{station}/intensity", [])]
    decisions = [codec.decode(StopDecision, p) for p in by_key.get(f"{station}/decision", [])]
    (summary,) = [codec.decode(RunSummary, p) for p in by_key[f"{station}/runs"]]
    (decision,) = decisions
    # every slip up to the decision is an event; none is reported after it (the tool stops)
    assert 0 < len(events) < len(trace.plateaus_n) - 1
    assert [event.index for event in events] == list(range(1, len(events) + 1))
    assert events[-1].time_ns <= decision.time_ns
    assert len(intensities) == len(events)
    assert events[-1].predictions and events[-1].run_id == 42
    assert {event.station for event in events} == {station}
    assert decision.station == station and decision.run_id == 42
    assert decision.reason == "plateau_closest"
    assert decision.force_n == pytest.approx(30_056.0, abs=150.0)
    assert summary.station == station and summary.program_id == PROGRAM_OF[station]
    if acted:
        assert (summary.stop_reason, summary.late_decision) == ("plateau_closest", None)
    else:  # the tool stopped by itself: the decision was late, not the stop reason
        assert (summary.stop_reason, summary.late_decision) == (None, "plateau_closest")
    assert summary.events == len(events)
    assert summary.samples == len(trace.rows())  # no sample of another station counted
    assert summary.error_pct is not None
    assert summary.reached_force_n == pytest.approx(trace.force_n[-1])
    # the run's result, published before its summary, on its own channel
    (result,) = [codec.decode(TighteningResult, p) for p in by_key[f"{station}/results"]]
    assert (result.station, result.run_id, result.source) == (station, 42, "predictor")
    assert result.final_force_n.value == summary.reached_force_n
    assert (result.events, result.stop_reason) == (summary.events, summary.stop_reason)
    assert result.result == "OK"  # no windows in these programs, no fault


def test_one_service_predicts_each_station_with_its_own_configuration(
    service: PredictorService, endpoint: str
) -> None:
    """pt1 and pt2 tighten run 42 at the same time; pt3 (not served) too."""
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    rows = trace.rows()
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        for station_id in PROGRAM_OF:
            wait_for_token(session, keys.health_key(station_id, "predictor"))
        assert not list(session.liveliness().get(keys.health_key("pt3", "predictor")))
        received = session.declare_subscriber("boltwatch/**", zenoh.handlers.FifoChannel(10_000))
        feeds = [StationFeed(session, "pt1"), StationFeed(session, "pt2")]
        unserved = StationFeed(session, "pt3", wait=False)
        feeds[0].sample(41, 0, rows[0])  # no run yet: dropped
        for feed in feeds:
            feed.state(42, PROGRAM_OF[feed.station_id], "running", START_NS)
        unserved.state(42, 1, "running", START_NS)
        for i, row in enumerate(rows):
            for feed in (*feeds, unserved):
                feed.sample(42, i, row)
        end_ns = START_NS + 2_000_000_000
        # pt1's acquisition sent the StopCommand; pt2's did not (the decision came late)
        feeds[0].state(42, PROGRAM_OF["pt1"], "done", end_ns, stop_command="plateau_closest")
        feeds[1].state(42, PROGRAM_OF["pt2"], "done", end_ns)
        unserved.state(42, 1, "done", end_ns)
        by_key = collect(received, until={"pt1/runs", "pt2/runs"})
        received.undeclare()
        for feed in (*feeds, unserved):
            feed.close()
    check_run(by_key, "pt1", trace)
    check_run(by_key, "pt2", trace, acted=False)
    predictor_topics = (
        channels.EVENTS.topic,
        channels.INTENSITY.topic,
        channels.DECISION.topic,
        channels.RUNS.topic,
        channels.RESULTS.topic,
    )
    assert not [key for key in by_key if key.startswith("pt3/") and key[4:] in predictor_topics]
    assert service.dropped_samples == 1
    assert service.bad_payloads == 0
    assert service.station_ids == ["pt1", "pt2"]


def test_a_sample_naming_another_station_is_ignored(
    service: PredictorService, endpoint: str
) -> None:
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        feed = StationFeed(session, "pt1")
        wrong = sample(42, 0, station="pt2", time_ns=START_NS)
        feed.samples.put(codec.encode(wrong))
        wait_until(lambda: service.bad_payloads > 0, "the sample counted bad", 10.0)
        feed.close()
    assert service.bad_payloads == 1
    assert service.dropped_samples == 0


def test_a_second_predictor_for_a_served_station_is_refused(
    service: PredictorService, stations: list[LoadedStation], endpoint: str
) -> None:
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt2", "predictor"))
        with pytest.raises(ConfigError, match="pt2 already have a predictor"):
            PredictorService(ServiceSkeleton("predictor", session), stations[1])


def test_a_run_whose_end_never_arrived_is_forgotten_when_the_next_starts(
    service: PredictorService, endpoint: str
) -> None:
    """A router outage swallowed run 41's ``done``: the next run of the station ends
    it (one tool, one run at a time), counted, instead of keeping it for ever."""
    rows = staircase().rows()
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        feed = StationFeed(session, "pt1")
        feed.state(41, PROGRAM_OF["pt1"], "running", START_NS)
        for i, row in enumerate(rows[:50]):
            feed.sample(41, i, row)
        feed.state(42, PROGRAM_OF["pt1"], "running", START_NS + 3_000_000_000)
        feed.sample(41, 50, rows[50])  # late: run 41 is gone
        wait_until(lambda: service.dropped_samples > 0, "the late sample dropped", 10.0)
        feed.close()
    assert service.unfinished_runs == 1
    assert service.dropped_samples == 1


def test_a_run_id_counts_once_however_its_state_flips(
    service: PredictorService, endpoint: str
) -> None:
    """A ToolStatus flipping for one run id gave a row (a summary) per flip."""
    rows = staircase().rows()
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        summaries = session.declare_subscriber(
            channels.RUNS.key("pt1"), zenoh.handlers.FifoChannel(100)
        )
        feed = StationFeed(session, "pt1")
        for flip in range(5):
            feed.state(42, PROGRAM_OF["pt1"], "running", START_NS + flip)
            for i, row in enumerate(rows[:20]):
                feed.sample(42, i, row)
            feed.state(42, PROGRAM_OF["pt1"], "done", START_NS + flip + 1)
        feed.state(43, PROGRAM_OF["pt1"], "running", START_NS + 10)
        feed.state(43, PROGRAM_OF["pt1"], "done", START_NS + 11)
        got = collect(summaries, until={"pt1/runs"}, settle_s=1.0)
        summaries.undeclare()
        feed.close()
    runs = [codec.decode(RunSummary, payload).run_id for payload in got["pt1/runs"]]
    assert runs == [42, 43]
    assert service.repeated_runs == 4
