"""The line's zenoh access control: who may put what, matched by certificate common name.

Default deny. Every known service (subjects below, one certificate each:
common name ``<station>-<role>``, or one of the line's services
``line-recorder``, ``line-viewer`` (the live view, ``serve recorder
--view-only``), ``line-monitor`` (``boltwatch status``, the operator) and
``line-opcua`` (the OPC UA server))
may declare subscribers, queryables and liveliness tokens under
``boltwatch/**`` and receive what is published there; only

- ``<st>-acquisition`` may put ``boltwatch/<st>/samples``, ``sample_batches``,
  ``tool``, ``bus`` and the predictor's keys ``events``, ``intensity``,
  ``decision``, ``runs``, ``results``, ``predictor`` (its stats) (it hosts the
  station's predictor: ``[predictor] placement = "edge"``, the default),
- ``<st>-predictor`` may put the predictor's keys (a line predictor,
  ``boltwatch serve predictor`` for a station with ``placement = "line"``; with
  its spool's counters, ``spool``),
- ``<st>-openprotocol`` may put what an Open Protocol bridge publishes for its
  station (``boltwatch serve openprotocol``: the run's samples, tool states,
  the advisory predictor's keys, the controller's result, tool data, alarms and
  its own stats; :func:`shared.contract.channels.topics_of` ``("openprotocol")``),
- ``<st>-plc`` may put ``boltwatch/<st>/part`` (the line's PLC, or a scanner at the
  station: the part that arrived), and so may ``<st>-rig`` (the simulated rig
  stands in for the PLC),
- ``line-recorder`` may put ``boltwatch/<st>/recorder``, ``quality/alert``,
  ``wear/**`` and ``spool/ack`` (what it has of a station's spool);
- ``line-opcua`` (the line's OPC UA server, ``boltwatch serve opcua``) may put
  ``boltwatch/<st>/alert/ack`` (who acknowledged an alert, for the recorder);
- the station's spooling services (``acquisition``, ``openprotocol``, a line
  ``predictor``) may put ``again/**`` too (what their spool sends again).

No one else may put a station's decision; in a plant of several lines the
router of another line (``--peer NAME=ST,...``: the common name of that
router's certificate and its line's stations) may put what its own line's
services may put for its own stations (it forwards them; its own access
control checked them on the way in), nothing for this line's stations.

Anyone else (another common name, a certificate for another station) gets
nothing through the router. The router enforces it on what enters it
(``ingress``); the subjects only mean something with mutual TLS, where the
common name is the verified certificate's.

``python -m services.router.access_control st1 st2 > acl.json5`` writes the
section for a line (config/security/access_control.json5 is the one for st1);
``... st1 st2 --peer line2-router=st3,st4`` for line 1 of a plant whose line 2
(router ``line2-router``) serves st3 and st4.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Mapping, Sequence
from typing import Any

from shared.contract import channels, keys

#: what a station's spool sends again (the spooling services: acquisition, openprotocol,
#: a line predictor)
AGAIN_TOPICS = (f"{keys.AGAIN}/**",)
ACQUISITION_TOPICS = (*channels.topics_of("acquisition"), *AGAIN_TOPICS)
PREDICTOR_TOPICS = channels.topics_of("predictor")
#: a line predictor spools what it puts, as the station's services do
LINE_PREDICTOR_TOPICS = (*PREDICTOR_TOPICS, *AGAIN_TOPICS)
BRIDGE_TOPICS = (*channels.topics_of("openprotocol"), *AGAIN_TOPICS)
#: the part at a station: the line's PLC (or scanner), and the rig in its place
PLC_TOPICS = channels.topics_of("plc")
RIG_TOPICS = channels.topics_of("rig")
#: its channels below ``wear/**`` (the alert) and the wear ledger's queryable
RECORDER_TOPICS = (
    *(topic for topic in channels.topics_of("recorder") if not topic.startswith(keys.WEAR)),
    keys.WEAR,
    f"{keys.WEAR}/**",
)
#: what the line's OPC UA server puts: an alert's acknowledgement
OPCUA_TOPICS = channels.topics_of("opcua")
OPCUA_SERVER = "line-opcua"
LINE_OBSERVERS = ("line-recorder", "line-viewer", "line-monitor", OPCUA_SERVER)

_DECLARATIONS = [
    "declare_subscriber",
    "declare_queryable",
    "liveliness_token",
    "declare_liveliness_subscriber",
    "liveliness_query",
    "query",
    "reply",
]


def station_subjects(station: str) -> dict[str, str]:
    """Role -> certificate common name of the services of ``station``."""
    roles = ("acquisition", "predictor", "openprotocol", "rig", "plc")
    return {role: f"{station}-{role}" for role in roles}


def line_access_control(
    stations: list[str], peers: Mapping[str, Sequence[str]] | None = None
) -> dict[str, Any]:
    """The ``access_control`` section of the router for ``stations``; ``peers``: the
    routers of the plant's other lines (certificate common name -> their stations)."""
    rules: list[dict[str, Any]] = [
        _rule("line-declarations", _DECLARATIONS, ["ingress", "egress"], [keys.EVERYTHING]),
        _rule("line-delivery", ["put", "delete"], ["egress"], [keys.EVERYTHING]),
    ]
    subjects: list[dict[str, Any]] = []
    policies: list[dict[str, Any]] = []
    everyone: list[str] = list(LINE_OBSERVERS)
    for name in LINE_OBSERVERS:
        subjects.append({"id": name, "cert_common_names": [name]})
    recorder_keys = [keys.station_key(st, topic) for st in stations for topic in RECORDER_TOPICS]
    rules.append(_rule("recorder-puts", ["put"], ["ingress"], recorder_keys))
    policies.append(
        {"id": "line-recorder-puts", "rules": ["recorder-puts"], "subjects": ["line-recorder"]}
    )
    opcua_keys = [keys.station_key(st, topic) for st in stations for topic in OPCUA_TOPICS]
    rules.append(_rule("opcua-puts", ["put"], ["ingress"], opcua_keys))
    policies.append({"id": "line-opcua-puts", "rules": ["opcua-puts"], "subjects": [OPCUA_SERVER]})
    for station in stations:
        names = station_subjects(station)
        for name in names.values():
            subjects.append({"id": name, "cert_common_names": [name]})
            everyone.append(name)
        for role, topics in (
            ("acquisition", ACQUISITION_TOPICS + PREDICTOR_TOPICS),  # + the edge predictor
            ("predictor", LINE_PREDICTOR_TOPICS),
            ("openprotocol", BRIDGE_TOPICS),
            ("plc", PLC_TOPICS),
            ("rig", RIG_TOPICS),
        ):
            rule_id = f"{station}-{role}-puts"
            rules.append(
                _rule(
                    rule_id,
                    ["put"],
                    ["ingress"],
                    [keys.station_key(station, t) for t in dict.fromkeys(topics)],
                )
            )
            policies.append({"id": rule_id, "rules": [rule_id], "subjects": [names[role]]})
    for router, its_stations in (peers or {}).items():
        subjects.append({"id": router, "cert_common_names": [router]})
        everyone.append(router)
        rule_id = f"{router}-forwards"
        forwarded = [
            keys.station_key(st, topic)
            for st in its_stations
            for topic in dict.fromkeys(
                (
                    *ACQUISITION_TOPICS,
                    *PREDICTOR_TOPICS,
                    *BRIDGE_TOPICS,
                    *PLC_TOPICS,
                    *RIG_TOPICS,
                    *RECORDER_TOPICS,
                    *OPCUA_TOPICS,
                )
            )
        ]
        rules.append(_rule(rule_id, ["put"], ["ingress"], forwarded))
        policies.append({"id": rule_id, "rules": [rule_id], "subjects": [router]})
    policies.insert(
        0, {"id": "line", "rules": ["line-declarations", "line-delivery"], "subjects": everyone}
    )
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }


def _rule(
    rule_id: str, messages: list[str], flows: list[str], key_exprs: list[str]
) -> dict[str, Any]:
    return {
        "id": rule_id,
        "permission": "allow",
        "messages": messages,
        "flows": flows,
        "key_exprs": key_exprs,
    }


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m services.router.access_control")
    parser.add_argument("stations", nargs="+", metavar="STATION", help="this line's stations")
    parser.add_argument(
        "--peer",
        action="append",
        default=[],
        metavar="ROUTER=ST,...",
        help="another line's router (its certificate's common name) and that line's stations",
    )
    args = parser.parse_args(argv)
    peers: dict[str, list[str]] = {}
    for peer in args.peer:
        router, _, stations = peer.partition("=")
        named = [station for station in stations.split(",") if station]
        if not router or not named or set(named) & set(args.stations):
            parser.error(f"--peer {peer}: expected ROUTER=ST,... naming the other line's stations")
        peers[router] = named
    header = "// zenoh access_control of the line, made by services/router/access_control.py\n"
    acl = line_access_control(args.stations, peers)
    sys.stdout.write(header + json.dumps(acl, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
