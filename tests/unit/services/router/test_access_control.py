"""The line's access control: who may put what (services/router/access_control.py)."""

from __future__ import annotations

import json

import pytest

from services.router.access_control import (
    ACQUISITION_TOPICS,
    AGAIN_TOPICS,
    BRIDGE_TOPICS,
    PLC_TOPICS,
    PREDICTOR_TOPICS,
    line_access_control,
)
from shared.contract import channels, keys
from tests.support.access_rules import common_names, put_keys_granted
from tests.support.paths import CONFIG

STATIONS = ["st1", "st2", "st3"]


def station_keys(station: str, topics: tuple[str, ...]) -> set[str]:
    return {keys.station_key(station, topic) for topic in topics}


@pytest.mark.parametrize("station", STATIONS)
def test_the_acquisition_hosts_the_stations_predictor_and_may_put_its_keys(station: str) -> None:
    """placement "edge" (the default): the station's predictor publishes from its acquisition."""
    acl = line_access_control(STATIONS)
    assert put_keys_granted(acl, f"{station}-acquisition") == station_keys(
        station, ACQUISITION_TOPICS + PREDICTOR_TOPICS
    )


@pytest.mark.parametrize("station", STATIONS)
def test_a_line_predictor_may_put_only_the_predictors_keys(station: str) -> None:
    """placement "line": ``boltwatch serve predictor`` presents ``<st>-predictor``; it spools
    what it puts, so it also puts its spool's counters and what its spool sends again."""
    acl = line_access_control(STATIONS)
    granted = put_keys_granted(acl, f"{station}-predictor")
    assert granted == station_keys(station, (*PREDICTOR_TOPICS, *AGAIN_TOPICS))
    assert {channels.SPOOL.key(station), keys.again_key(station, "**")} <= granted
    assert not {channels.SAMPLES.key(station), channels.TOOL.key(station)} & granted


@pytest.mark.parametrize("station", STATIONS)
def test_an_open_protocol_bridge_may_put_what_a_bridge_publishes(station: str) -> None:
    """``boltwatch serve openprotocol`` presents ``<st>-openprotocol``: the run's samples and
    tool states, the advisory predictor's keys, the controller's result, tool data, alarms."""
    acl = line_access_control(STATIONS)
    granted = put_keys_granted(acl, f"{station}-openprotocol")
    assert granted == station_keys(station, BRIDGE_TOPICS)
    assert channels.TOOL_DATA.key(station) in granted and channels.BUS.key(station) not in granted


@pytest.mark.parametrize("station", STATIONS)
def test_only_the_lines_plc_and_the_rig_in_its_place_may_put_a_stations_part(
    station: str,
) -> None:
    """The part at a station names the part in every result: the line's PLC (or scanner)
    presents ``<st>-plc``; the simulated rig stands in for it and may put nothing else."""
    acl = line_access_control(STATIONS)
    assert (channels.PART.topic,) == PLC_TOPICS
    part = channels.PART.key(station)
    for role in ("plc", "rig"):
        assert put_keys_granted(acl, f"{station}-{role}") == {part}
    putters = {name for name in common_names(acl) if part in put_keys_granted(acl, name)}
    assert putters == {f"{station}-plc", f"{station}-rig"}
    other = next(st for st in STATIONS if st != station)
    assert channels.PART.key(other) not in put_keys_granted(acl, f"{station}-plc")


@pytest.mark.parametrize("station", STATIONS)
def test_no_other_identity_may_put_a_stations_decision(station: str) -> None:
    """The bridge's decisions are advisory: an acquisition never turns one into a stop."""
    acl = line_access_control(STATIONS)
    decision = channels.DECISION.key(station)
    deciders = {name for name in common_names(acl) if decision in put_keys_granted(acl, name)}
    roles = ("acquisition", "predictor", "openprotocol")
    assert deciders == {f"{station}-{role}" for role in roles}
    assert not any(decision in put_keys_granted(acl, n) for n in ("rogue", "router"))


def test_the_shipped_access_control_is_the_one_made_for_st1() -> None:
    """config/security/access_control.json5 is ``python -m services.router.access_control st1``."""
    text = (CONFIG / "security" / "access_control.json5").read_text()
    header, body = text.split("\n", 1)
    assert header.startswith("//")
    assert json.loads(body) == line_access_control(["st1"])


def test_another_lines_router_may_forward_its_own_stations_only() -> None:
    """A plant: line 1's router takes from line 2's router what line 2's services may put
    for line 2's stations (samples, decisions, recorder stats, wear alerts), nothing for st1."""
    acl = line_access_control(["st1"], {"line2-router": ["st2", "st3"]})
    granted = put_keys_granted(acl, "line2-router")
    assert channels.SAMPLES.key("st2") in granted
    assert channels.DECISION.key("st3") in granted
    assert channels.PART.key("st2") in granted  # its PLC's (or rig's) parts
    assert keys.station_key("st3", f"{keys.WEAR}/**") in granted
    assert not any(key.startswith("boltwatch/st1/") for key in granted)
    line = next(policy for policy in acl["policies"] if policy["id"] == "line")
    assert "line2-router" in line["subjects"]  # declarations, queries, replies, delivery
    decision = channels.DECISION.key("st1")
    deciders = {name for name in common_names(acl) if decision in put_keys_granted(acl, name)}
    assert deciders == {"st1-acquisition", "st1-predictor", "st1-openprotocol"}


def test_a_peer_naming_this_lines_station_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    from services.router.access_control import main

    with pytest.raises(SystemExit) as exit_info:
        main(["st1", "--peer", "line2-router=st1"])
    assert exit_info.value.code == 2
    assert "--peer line2-router=st1" in capsys.readouterr().err
    assert main(["st1", "--peer", "line2-router=st2"]) == 0
    assert '"line2-router-forwards"' in capsys.readouterr().out


def test_the_lines_opcua_server_may_put_its_stations_alert_acknowledgements_only() -> None:
    """``boltwatch serve opcua`` presents ``line-opcua``: an OPC UA client's acknowledgement
    of an alert goes on the line, for the recorder; it puts nothing else. Another line's
    router forwards its own line's."""
    acl = line_access_control(STATIONS, {"line2-router": ["st4"]})
    assert put_keys_granted(acl, "line-opcua") == {channels.ALERT_ACK.key(st) for st in STATIONS}
    line = next(policy for policy in acl["policies"] if policy["id"] == "line")
    assert "line-opcua" in line["subjects"]  # declarations (its subscriptions), delivery
    assert channels.ALERT_ACK.key("st4") in put_keys_granted(acl, "line2-router")
