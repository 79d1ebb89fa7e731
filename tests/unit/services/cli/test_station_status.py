"""boltwatch status, the pure part: what a window of messages adds up to, and how it reads."""

from __future__ import annotations

import json
from typing import Any

from services.cli.station_status_text import format_report
from shared.contract import (
    BusStats,
    PredictorStats,
    RecorderStats,
    StopDecision,
    ToolState,
    channels,
    encode,
    keys,
)
from shared.line_status import LastRun, StatusCollector, to_json
from tests.support.factories import T0, S, sample, summary


def bus(time_ns: int, samples: int, **counters: Any) -> BusStats:
    fields: dict[str, Any] = {
        "frames": 2 * samples,
        "unknown_ids": 0,
        "wrong_length": 0,
        "decode_errors": 0,
        "error_frames": 0,
        "receive_errors": 0,
        "counter_gaps": 0,
        "missed_samples": 0,
        "counter_faults": 0,
        "unpaired": 0,
        "orphans": 0,
        "stop_commands": 0,
    }
    fields.update(counters)
    return BusStats(station="st1", time_ns=time_ns, samples=samples, **fields)


def feed(collector: StatusCollector, topic: str, message: Any, at_ns: int = T0) -> None:
    collector.message(keys.station_key("st1", topic), encode(message), at_ns)


def test_services_from_liveliness_tokens_known_ones_always_listed() -> None:
    collector = StatusCollector()
    collector.alive(keys.health_key("st1", "acquisition"))
    collector.alive(keys.health_key("st1", "predictor"))
    collector.alive(keys.health_key("st2", "recorder"))
    collector.alive(keys.health_key("st2", "wear-dashboard"))
    collector.alive("elsewhere/st1/health/rig")  # not ours: ignored

    report = collector.report("tcp/127.0.0.1:7447", 2.0, T0)

    assert [s.station for s in report.stations] == ["st1", "st2"]
    st1, st2 = report.stations
    assert st1.services == {
        "acquisition": True,
        "predictor": True,
        "recorder": False,
        "rig": False,
    }
    assert st2.services["recorder"] and st2.services["wear-dashboard"]
    assert list(st2.services)[:4] == ["acquisition", "predictor", "recorder", "rig"]
    assert st1.bus is None and st1.last_run is None and st1.samples_per_s == 0.0


def test_sample_rate_from_samples_and_from_bus_stats_deltas() -> None:
    collector = StatusCollector()
    for sequence in range(1500):
        feed(collector, channels.SAMPLES.topic, sample(4, sequence))
    feed(collector, channels.BUS.topic, bus(T0, samples=10_000))
    feed(collector, channels.BUS.topic, bus(T0 + 2 * S, samples=12_000))

    (status,) = collector.report("e", 1.5, T0 + 2 * S).stations

    assert status.samples_per_s == 1000.0
    assert status.bus_samples_per_s == 1000.0


def test_bus_rate_unknown_with_one_bus_stats_or_a_restarted_acquisition() -> None:
    one = StatusCollector()
    feed(one, channels.BUS.topic, bus(T0, samples=10))
    assert one.report("e", 2.0, T0).stations[0].bus_samples_per_s is None

    restarted = StatusCollector()
    feed(restarted, channels.BUS.topic, bus(T0, samples=5000))
    feed(restarted, channels.BUS.topic, bus(T0 + S, samples=20))
    assert restarted.report("e", 2.0, T0).stations[0].bus_samples_per_s is None


def test_faults_come_from_the_latest_bus_stats() -> None:
    collector = StatusCollector()
    feed(collector, channels.BUS.topic, bus(T0, samples=100, counter_gaps=1, missed_samples=2))
    latest = bus(
        T0 + S,
        samples=1100,
        counter_gaps=3,
        missed_samples=7,
        wrong_length=1,
        decode_errors=2,
        error_frames=4,
        counter_faults=8,
        unknown_ids=50,
        receive_errors=1,
    )
    feed(collector, channels.BUS.topic, latest, at_ns=T0 + S)

    (status,) = collector.report("e", 2.0, T0 + 2 * S).stations

    assert status.bus is not None
    assert (status.bus.counter_gaps, status.bus.missed_samples) == (3, 7)
    assert status.bus.bad_frames == 1 + 2 + 4 + 8  # foreign unknown ids are not bad frames
    assert status.bus.unknown_ids == 50 and status.bus.receive_errors == 1
    assert status.bus.age_s == 1.0


def test_last_run_prefers_tool_state_then_samples_then_summary() -> None:
    collector = StatusCollector()
    feed(collector, channels.RUNS.topic, summary(3))
    assert collector.report("e", 2.0, T0).stations[0].last_run == _run(3, "done", 7, 1, "runs")

    feed(collector, channels.SAMPLES.topic, sample(4, 0))
    feed(collector, channels.SAMPLES.topic, sample(4, 1))
    assert collector.report("e", 2.0, T0).stations[0].last_run == _run(
        4, "running", None, None, "samples"
    )

    feed(collector, channels.TOOL.topic, ToolState("st1", 4, 7, 2, "running", T0))
    assert collector.report("e", 2.0, T0).stations[0].last_run == _run(4, "running", 7, 2, "tool")


def _run(run_id: int, state: str, tool: int | None, program: int | None, source: str) -> LastRun:
    return LastRun(run_id, state, tool, program, source)


def test_last_decision_and_summary_with_their_ages() -> None:
    collector = StatusCollector()
    decision = StopDecision(
        "st1", 3, T0, 2.4, "plateau_closest", "next plateau farther", 190.0, 55800.0, 57100.0, T0
    )
    feed(collector, channels.DECISION.topic, decision)
    feed(collector, channels.RUNS.topic, summary(3, ended_ns=T0 + S // 2))

    (status,) = collector.report("e", 2.0, T0 + 3 * S).stations

    assert status.last_decision is not None and status.last_summary is not None
    assert (status.last_decision.run_id, status.last_decision.reason) == (3, "plateau_closest")
    assert status.last_decision.age_s == 3.0
    last = status.last_summary
    assert (last.unit, last.target, last.reached, last.error_pct) == ("N", 56000, 55800, -0.357)
    assert last.age_s == 2.5
    assert status.recorder is None


def test_torque_only_summary_reports_torque() -> None:
    collector = StatusCollector()
    feed(
        collector,
        channels.RUNS.topic,
        summary(5, target_force_n=None, reached_force_n=None, stop_reason=None),
    )
    (status,) = collector.report("e", 2.0, T0).stations
    assert status.last_summary is not None
    assert (status.last_summary.unit, status.last_summary.target) == ("Nm", 200.0)
    assert status.last_summary.reached == 190.0
    assert "tool stopped itself (done)" in format_report(collector.report("e", 2.0, T0))


def test_unreadable_messages_are_counted_not_fatal() -> None:
    collector = StatusCollector()
    collector.message("boltwatch/st1/bus", b"{not json", T0)
    collector.message("boltwatch/st1/decision", b'{"station": "st1"}', T0)
    collector.message("boltwatch/st1/samples", b"garbage", T0)
    collector.message("boltwatch/st1/events", b"anything", T0)  # not aggregated: just seen
    collector.message("not/ours", b"x", T0)

    (status,) = collector.report("e", 2.0, T0).stations

    assert status.unreadable_messages == 3
    assert status.bus is None and status.last_decision is None and status.last_run is None


def test_json_is_one_object_keyed_by_station() -> None:
    collector = StatusCollector()
    collector.alive(keys.health_key("st1", "acquisition"))
    feed(collector, channels.BUS.topic, bus(T0, samples=10, missed_samples=1))
    feed(collector, channels.TOOL.topic, ToolState("st1", 4, 7, 1, "running", T0))

    data = json.loads(json.dumps(to_json(collector.report("tcp/h:1", 2.0, T0))))

    assert data["endpoint"] == "tcp/h:1" and data["listened_s"] == 2.0
    st1 = data["stations"]["st1"]
    assert st1["services"]["acquisition"] is True and st1["services"]["rig"] is False
    assert st1["bus"]["missed_samples"] == 1
    assert st1["last_run"] == {
        "run_id": 4,
        "state": "running",
        "tool_id": 7,
        "program_id": 1,
        "source": "tool",
    }
    assert st1["last_decision"] is None and st1["recorder"] is None


def test_table_reads_per_station() -> None:
    collector = StatusCollector()
    collector.alive(keys.health_key("st1", "acquisition"))
    for sequence in range(2000):
        feed(collector, channels.SAMPLES.topic, sample(4, sequence))
    feed(collector, channels.BUS.topic, bus(T0, samples=0))
    feed(
        collector,
        channels.BUS.topic,
        bus(T0 + S, samples=1000, counter_gaps=2, missed_samples=3, late_decisions=1),
    )
    feed(collector, channels.RUNS.topic, summary(3))

    text = format_report(collector.report("tcp/127.0.0.1:7447", 2.0, T0 + S))

    assert text.startswith("connected to tcp/127.0.0.1:7447, listened 2.0 s")
    assert "station st1" in text
    assert "acquisition up, predictor DOWN, recorder DOWN, rig DOWN" in text
    assert "1000 received (bus 1000)" in text
    assert "2 gaps, 3 missed samples, 0 bad frames" in text
    assert "0 unsent samples, 1 late decisions" in text
    assert "run 3: 55.80 kN of 56.00 kN target, error -0.36 %, plateau_closest" in text
    assert "recorder      - (no recorder stats in the window" in text


def test_nothing_seen_says_so() -> None:
    text = format_report(StatusCollector().report("tcp/127.0.0.1:7447", 2.0, T0))
    assert "no station seen" in text
    assert to_json(StatusCollector().report("e", 2.0, T0))["stations"] == {}


def recorder_stats(time_ns: int, **changes: Any) -> RecorderStats:
    fields: dict[str, Any] = {
        "station": "st1",
        "time_ns": time_ns,
        "messages": 12_345,
        "lag_p50_ms": 1.25,
        "lag_max_ms": 7.5,
        "write_errors": 0,
        "last_error": None,
        "recording": True,
    }
    fields.update(changes)
    return RecorderStats(**fields)


def test_recorder_lag_and_health_come_from_the_latest_recorder_stats() -> None:
    collector = StatusCollector()
    feed(collector, channels.RECORDER.topic, recorder_stats(T0, lag_p50_ms=9.0), at_ns=T0)
    feed(collector, channels.RECORDER.topic, recorder_stats(T0 + S), at_ns=T0 + S)

    report = collector.report("e", 2.0, T0 + 2 * S)
    (status,) = report.stations

    assert status.recorder is not None
    assert (status.recorder.lag_p50_ms, status.recorder.lag_max_ms) == (1.25, 7.5)
    assert (status.recorder.messages, status.recorder.recording) == (12_345, True)
    assert status.recorder.age_s == 1.0
    text = format_report(report)
    assert "recorder      recording, lag p50 1.2 ms, max 7.5 ms, 12345 messages, " in text
    assert to_json(report)["stations"]["st1"]["recorder"]["lag_max_ms"] == 7.5


def test_a_recorder_that_cannot_write_says_so_and_why() -> None:
    collector = StatusCollector()
    failing = recorder_stats(
        T0,
        lag_p50_ms=None,
        lag_max_ms=None,
        write_errors=3,
        last_error="[Errno 28] No space left on device",
        recording=False,
        missing_samples=42,
    )
    feed(collector, channels.RECORDER.topic, failing)
    collector.message("boltwatch/st1/recorder", b"{broken", T0)

    report = collector.report("e", 2.0, T0)
    (status,) = report.stations

    assert status.recorder is not None and not status.recorder.recording
    assert status.unreadable_messages == 1
    text = format_report(report)
    assert "NOT RECORDING: [Errno 28] No space left on device (lag - (no samples)" in text
    assert "3 write errors" in text
    assert "42 samples missing" in text


def test_a_broken_wear_ledger_and_refused_summaries_show_while_recording_goes_on() -> None:
    broken = (
        "wear ledger: recordings/wear.sqlite: not a usable wear ledger: it is empty (0 bytes); "
        "move it aside and start a new ledger: boltwatch wear reset --recordings recordings"
    )
    stats = recorder_stats(
        T0, last_error=broken, write_errors=1, refused_summaries=2, waiting_summaries=3
    )
    collector = StatusCollector()
    feed(collector, channels.RECORDER.topic, stats)

    report = collector.report("e", 2.0, T0)
    (status,) = report.stations
    assert status.recorder is not None and status.recorder.recording
    text = format_report(report)
    assert "recorder      recording, lag p50 1.2 ms" in text
    assert "2 run summaries refused by the wear ledger, 3 runs waiting for the wear ledger" in text
    assert text.rstrip().endswith(f"last error: {broken}")
    recorder = to_json(report)["stations"]["st1"]["recorder"]
    assert (recorder["refused_summaries"], recorder["waiting_summaries"]) == (2, 3)


def test_summaries_the_wear_ledger_refused_show() -> None:
    collector = StatusCollector()
    feed(collector, channels.RECORDER.topic, recorder_stats(T0, refused_summaries=2))
    report = collector.report("e", 2.0, T0)
    text = format_report(report)
    assert "0 write errors, 2 run summaries refused by the wear ledger, " in text
    assert to_json(report)["stations"]["st1"]["recorder"]["refused_summaries"] == 2


def test_what_the_retention_policy_deleted_and_kept_shows() -> None:
    collector = StatusCollector()
    stats = recorder_stats(T0, recordings_deleted=212, recordings_kept_unstored=3)
    feed(collector, channels.RECORDER.topic, stats)
    report = collector.report("e", 2.0, T0)
    text = format_report(report)
    assert (
        "212 recordings deleted by the retention policy, 3 recordings past their time kept: "
        "results not stored, " in text
    )
    recorder = to_json(report)["stations"]["st1"]["recorder"]
    assert (recorder["recordings_deleted"], recorder["recordings_kept_unstored"]) == (212, 3)
    feed(collector, channels.RECORDER.topic, recorder_stats(T0 + S))
    assert "retention" not in format_report(collector.report("e", 2.0, T0 + S))


def test_the_stations_line_and_the_results_waiting_for_their_store_show() -> None:
    collector = StatusCollector()
    feed(collector, channels.RECORDER.topic, recorder_stats(T0, line="B", waiting_results=7))
    report = collector.report("e", 2.0, T0)
    text = format_report(report)
    assert "station st1 (line B)\n" in text
    assert ", 7 results waiting for the results store" in text
    assert to_json(report)["stations"]["st1"]["recorder"]["line"] == "B"
    feed(collector, channels.RECORDER.topic, recorder_stats(T0 + S))
    assert "station st1\n" in format_report(collector.report("e", 2.0, T0 + S))


def test_the_stations_plant_and_name_show_beside_its_id() -> None:
    collector = StatusCollector()
    stats = recorder_stats(T0, plant="North", line="B", station_name="Wheel nuts, left")
    feed(collector, channels.RECORDER.topic, stats)
    report = collector.report("e", 2.0, T0)
    assert 'station st1 "Wheel nuts, left" (plant North, line B)\n' in format_report(report)
    recorder = to_json(report)["stations"]["st1"]["recorder"]
    assert (recorder["plant"], recorder["station_name"]) == ("North", "Wheel nuts, left")
    feed(collector, channels.RECORDER.topic, recorder_stats(T0 + S, plant="North"))
    assert "station st1 (plant North)\n" in format_report(collector.report("e", 2.0, T0 + S))


def test_what_each_service_refused_is_shown() -> None:
    """Bad decisions (BusStats), the predictor's bad payloads and samples (PredictorStats),
    the recorder's refused payloads (RecorderStats): counted where they were refused."""
    collector = StatusCollector()
    feed(collector, channels.BUS.topic, bus(T0, samples=10, bad_decisions=4))
    feed(collector, channels.RECORDER.topic, recorder_stats(T0, bad_payloads=17))
    stats = PredictorStats("st1", T0, T0 - 60 * S, 5, 2, 1, 0, 0)
    feed(collector, channels.PREDICTOR.topic, stats, at_ns=T0 - S)

    report = collector.report("e", 2.0, T0)
    (status,) = report.stations

    assert status.bus is not None and status.bus.bad_decisions == 4
    assert status.recorder is not None and status.recorder.bad_payloads == 17
    assert status.predictor is not None
    assert (status.predictor.bad_payloads, status.predictor.bad_samples) == (5, 2)
    text = format_report(report)
    assert "0 late decisions, 4 bad decisions" in text
    assert "predictor     5 bad payloads, 2 bad samples, 1 samples without a run, " in text
    assert "0 unfinished runs (1.0 s ago)" in text
    assert "17 bad payloads" in text
    assert to_json(report)["stations"]["st1"]["predictor"]["bad_samples"] == 2
    quiet = StatusCollector()
    feed(quiet, channels.BUS.topic, bus(T0, samples=1))
    text = format_report(quiet.report("e", 2.0, T0))
    assert "predictor     - (no predictor stats in the window" in text


def test_what_the_station_commands_its_tool_is_said() -> None:
    """A final stage, or stop only and why (the latest BusStats); a controller's station
    commands nothing."""
    staged = StatusCollector()
    feed(staged, channels.BUS.topic, bus(T0, 100, tool_commands="staged", stage_commands=12))
    text = format_report(staged.report("e", 2.0, T0 + S))
    assert "  tool commands final stage and pulses (12 stage commands sent)\n" in text
    stop_only = StatusCollector()
    note = "the tool controller sends no ToolStage"
    feed(stop_only, channels.BUS.topic, bus(T0, 100, tool_commands_note=note))
    text = format_report(stop_only.report("e", 2.0, T0 + S))
    assert f"  tool commands stop only: {note}\n" in text
    bridge = StatusCollector()
    bridge.alive(keys.station_key("st1", "health/openprotocol"))
    assert "tool commands none: an Open Protocol controller" in format_report(
        bridge.report("e", 2.0, T0 + S)
    )
