"""boltwatch status and the line's page: a station's spool, what waits, and its alert."""

from __future__ import annotations

import dataclasses
from typing import Any

from services.cli.station_status_text import format_report
from shared.contract import SpoolStats, encode, keys
from shared.line_status import StatusCollector, to_json
from tests.support.factories import T0, S
from tests.support.fuzz.payloads import template


def stats(**changes: Any) -> SpoolStats:
    made: SpoolStats = template("spool", "st1", T0)
    return dataclasses.replace(made, **changes)


def report_of(*sent: SpoolStats) -> dict[str, Any]:
    collector = StatusCollector()
    for message in sent:
        collector.message(keys.station_key("st1", "spool"), encode(message), T0 + S)
    report = collector.report("tcp/127.0.0.1:7447", 2.0, T0 + 2 * S)
    text = format_report(report)
    view = to_json(report)["stations"]["st1"]
    return {"text": text, "spools": view["spools"]}


def test_what_waits_for_the_recorder_is_shown_with_its_oldest_run() -> None:
    shown = report_of(
        stats(
            messages=40,
            runs=2,
            samples=1500,
            bytes=2_000_000,
            max_bytes=4_000_000_000,
            oldest_run_id=41,
            oldest_ns=T0 - 63 * S,
            resend_rate=200.0,
            acknowledged_ns=T0,
        )
    )
    (spool,) = shown["spools"]
    assert spool["runs"] == 2 and spool["samples"] == 1500 and spool["oldest_run_id"] == 41
    assert spool["oldest_age_s"] == 63.0 and spool["alert"] is None
    (line,) = [line for line in str(shown["text"]).splitlines() if "spool" in line]
    assert line.split()[:2] == ["spool", "acquisition:"]
    assert line.endswith(
        "acquisition: 2 runs, 1500 samples wait for the recorder, oldest run 41 waiting 63 s, "
        "2.0 MB of 4.00 GB (0.1 %), sending again 200/s"
    )


def test_a_spool_past_eighty_percent_or_that_dropped_raises_the_alert() -> None:
    full = report_of(stats(bytes=850, max_bytes=1000, dropped_samples=0, dropped_messages=0))
    assert full["spools"][0]["alert"] == "85 % full"
    dropped = report_of(stats(dropped_samples=1200, dropped_messages=24))
    alert = dropped["spools"][0]["alert"]
    assert alert == "dropped 1200 samples (24 messages) to keep its bound"
    assert "ALERT: dropped 1200 samples" in str(dropped["text"])


def test_the_latest_counters_of_each_source_count() -> None:
    shown = report_of(
        stats(messages=5, time_ns=T0),
        stats(messages=0, time_ns=T0 + S),
        stats(source="openprotocol", messages=3),
    )
    spools = shown["spools"]
    assert [(s["source"], s["messages"]) for s in spools] == [
        ("acquisition", 0),
        ("openprotocol", 3),
    ]
    assert "nothing waits for the recorder" in str(shown["text"])
