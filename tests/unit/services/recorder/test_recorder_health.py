"""Missing samples counted end to end: BusStats' published count against samples received."""

from __future__ import annotations

from services.recorder.live.recorder_health import RecorderHealth
from shared.config import StationPlace

T0 = 1_700_000_000_000_000_000


STARTED = T0 - 60_000_000_000  # the acquisition process's start


def receive(health: RecorderHealth, samples: int, station: str = "st1") -> None:
    for _ in range(samples):
        health.written(station, T0 + 1_000_000, T0, is_sample=True)


def bus(
    health: RecorderHealth, published: int, station: str = "st1", started: int = STARTED
) -> None:
    health.bus_stats(station, published, started)


def missing(health: RecorderHealth, station: str = "st1") -> int:
    (stats,) = [s for s in health.report(T0, 0, None, True) if s.station == station]
    return stats.missing_samples


def test_every_published_sample_received_is_no_loss() -> None:
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 1000)
    bus(health, 1000)
    assert missing(health) == 0


def test_samples_lost_on_the_way_are_counted_exactly() -> None:
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 700)
    bus(health, 1000)  # 300 never came: a cable pulled, no link loss seen
    assert missing(health) == 300
    receive(health, 1000)
    bus(health, 2000)
    assert missing(health) == 300


def test_samples_in_flight_count_for_one_report_only() -> None:
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 990)
    bus(health, 1000)  # ten still on their way
    assert missing(health) == 10
    receive(health, 10)
    bus(health, 1000)
    assert missing(health) == 0


def test_what_was_published_before_the_recorder_listened_is_not_a_loss() -> None:
    health = RecorderHealth(["st1"])
    receive(health, 5)  # the tail of a run the recorder joined late
    bus(health, 50_000)
    receive(health, 1000)
    bus(health, 51_000)
    assert missing(health) == 0


def test_an_acquisition_restart_keeps_the_loss_and_counts_afresh() -> None:
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 900)
    bus(health, 1000)
    assert missing(health) == 100
    bus(health, 0, started=T0)  # a new acquisition process: its count starts at 0
    receive(health, 480)
    bus(health, 500, started=T0)
    assert missing(health) == 120


def test_a_restart_is_seen_even_when_the_new_count_is_not_lower() -> None:
    """The recorder was cut off while the acquisition restarted: by the new process's
    first report it has published more than the old one had; started_ns tells."""
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 90)
    bus(health, 100)
    assert missing(health) == 10
    receive(health, 3000)  # the new process's samples, heard once the link is back
    bus(health, 3000, started=T0)
    receive(health, 1000)
    bus(health, 4000, started=T0)
    assert missing(health) == 10


def test_an_undecodable_sample_is_received_not_missing() -> None:
    health = RecorderHealth(["st1"])
    bus(health, 0)
    receive(health, 9)
    health.written("st1", T0, None, is_sample=True)  # recorded raw
    bus(health, 10)
    assert missing(health) == 0


def test_stations_are_counted_apart() -> None:
    health = RecorderHealth(["st1", "st2"])
    bus(health, 0)
    bus(health, 0, "st2")
    receive(health, 1000, "st1")
    receive(health, 400, "st2")
    bus(health, 1000)
    bus(health, 1000, "st2")
    assert missing(health, "st1") == 0
    assert missing(health, "st2") == 600


def test_each_station_is_placed_as_its_station_file_says() -> None:
    place = StationPlace("North", "B", "Wheel nuts")
    health = RecorderHealth(["st1", "st2"], {"st1": place})
    receive(health, 1, "st3")  # another line's station, heard: placed nowhere
    stats = {s.station: s for s in health.report(T0, 0, None, True)}
    assert StationPlace(stats["st1"].plant, stats["st1"].line, stats["st1"].station_name) == place
    for station in ("st2", "st3"):
        assert (stats[station].plant, stats[station].line, stats[station].station_name) == (
            "",
            "",
            "",
        )
