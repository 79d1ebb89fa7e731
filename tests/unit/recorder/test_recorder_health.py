"""Missing samples counted end to end: BusStats' published count against samples received."""

from __future__ import annotations

from services.recorder.recorder_health import RecorderHealth

T0 = 1_700_000_000_000_000_000


def receive(health: RecorderHealth, samples: int, station: str = "st1") -> None:
    for _ in range(samples):
        health.written(station, T0 + 1_000_000, T0)


def missing(health: RecorderHealth, station: str = "st1") -> int:
    (stats,) = [s for s in health.report(T0, 0, None, True) if s.station == station]
    return stats.missing_samples


def test_every_published_sample_received_is_no_loss() -> None:
    health = RecorderHealth(["st1"])
    health.bus_stats("st1", 0)
    receive(health, 1000)
    health.bus_stats("st1", 1000)
    assert missing(health) == 0


def test_samples_lost_on_the_way_are_counted_exactly() -> None:
    health = RecorderHealth(["st1"])
    health.bus_stats("st1", 0)
    receive(health, 700)
    health.bus_stats("st1", 1000)  # 300 never came: a cable pulled, no link loss seen
    assert missing(health) == 300
    receive(health, 1000)
    health.bus_stats("st1", 2000)
    assert missing(health) == 300


def test_samples_in_flight_count_for_one_report_only() -> None:
    health = RecorderHealth(["st1"])
    health.bus_stats("st1", 0)
    receive(health, 990)
    health.bus_stats("st1", 1000)  # ten still on their way
    assert missing(health) == 10
    receive(health, 10)
    health.bus_stats("st1", 1000)
    assert missing(health) == 0


def test_what_was_published_before_the_recorder_listened_is_not_a_loss() -> None:
    health = RecorderHealth(["st1"])
    receive(health, 5)  # the tail of a run the recorder joined late
    health.bus_stats("st1", 50_000)
    receive(health, 1000)
    health.bus_stats("st1", 51_000)
    assert missing(health) == 0


def test_an_acquisition_restart_keeps_the_loss_and_counts_afresh() -> None:
    health = RecorderHealth(["st1"])
    health.bus_stats("st1", 0)
    receive(health, 900)
    health.bus_stats("st1", 1000)
    assert missing(health) == 100
    health.bus_stats("st1", 0)  # a new acquisition process: its count starts at 0
    receive(health, 480)
    health.bus_stats("st1", 500)
    assert missing(health) == 120


def test_stations_are_counted_apart() -> None:
    health = RecorderHealth(["st1", "st2"])
    health.bus_stats("st1", 0)
    health.bus_stats("st2", 0)
    receive(health, 1000, "st1")
    receive(health, 400, "st2")
    health.bus_stats("st1", 1000)
    health.bus_stats("st2", 1000)
    assert missing(health, "st1") == 0
    assert missing(health, "st2") == 600
