"""A station as its joining system's Identification (pure): its name, id, place in the plant
and what reads its tool."""

from __future__ import annotations

from services.opcua.system_identification import SystemIdentification, system_identification
from shared.config import load_any_station
from tests.support.paths import CONFIG, STATION_FILE


def test_a_can_station_in_the_plant_model() -> None:
    station = load_any_station(STATION_FILE)
    placed = station.config.station.model_copy(
        update={"plant": "North", "line": "B", "name": "Wheel bolts 1"}
    )
    station.config = station.config.model_copy(update={"station": placed})
    assert system_identification(station) == SystemIdentification(
        name="Wheel bolts 1",
        system_id="st1",
        location="plant North, line B",
        description="tightening station st1: torque, angle and preload over CAN, "
        "stopped by boltwatch",
        joining_technology="Tightening",
    )


def test_a_controller_station_without_a_place_is_named_by_its_id() -> None:
    station = load_any_station(CONFIG / "controller-station.toml")
    link = station.config.openprotocol
    assert link is not None
    identification = system_identification(station)
    assert (identification.name, identification.system_id) == ("op1", "op1")
    assert identification.location is None
    assert identification.description == (
        f"tightening station op1: an Open Protocol controller at {link.host}:{link.port}, "
        "read by boltwatch"
    )
