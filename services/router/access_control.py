"""The line's zenoh access control: who may put what, matched by certificate common name.

Default deny. Every known service (subjects below, one certificate each:
common name ``<station>-<role>``, or one of the line's observers
``line-recorder``, ``line-viewer`` (the live view, ``serve recorder
--view-only``) and ``line-monitor`` (``boltwatch status``, the operator))
may declare subscribers, queryables and liveliness tokens under
``boltwatch/**`` and receive what is published there; only

- ``<st>-acquisition`` may put ``boltwatch/<st>/samples``, ``tool``, ``bus``
  and the predictor's keys ``events``, ``intensity``, ``decision``, ``runs``,
  ``predictor`` (its stats) (it hosts the station's predictor:
  ``[predictor] placement = "edge"``, the default),
- ``<st>-predictor`` may put the predictor's keys (a line predictor,
  ``boltwatch serve predictor`` for a station with ``placement = "line"``),
- ``line-recorder`` may put ``boltwatch/<st>/recorder`` and ``wear/**``.

No one else may put a station's decision.

Anyone else (another common name, a certificate for another station) gets
nothing through the router. The router enforces it on what enters it
(``ingress``); the subjects only mean something with mutual TLS, where the
common name is the verified certificate's.

``python -m services.router.access_control st1 st2 > acl.json5`` writes the
section for a line (config/security/access_control.json5 is the one for st1).
"""

from __future__ import annotations

import json
import sys
from typing import Any

from shared import keys

ACQUISITION_TOPICS = (keys.SAMPLES, keys.SAMPLE_BATCHES, keys.TOOL, keys.BUS)
PREDICTOR_TOPICS = (keys.EVENTS, keys.INTENSITY, keys.DECISION, keys.RUNS, keys.PREDICTOR)
RECORDER_TOPICS = (keys.RECORDER, keys.WEAR, f"{keys.WEAR}/**")
LINE_OBSERVERS = ("line-recorder", "line-viewer", "line-monitor")

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
    return {role: f"{station}-{role}" for role in ("acquisition", "predictor", "rig")}


def line_access_control(stations: list[str]) -> dict[str, Any]:
    """The ``access_control`` section of the router for ``stations``."""
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
    for station in stations:
        names = station_subjects(station)
        for name in names.values():
            subjects.append({"id": name, "cert_common_names": [name]})
            everyone.append(name)
        for role, topics in (
            ("acquisition", ACQUISITION_TOPICS + PREDICTOR_TOPICS),  # + the edge predictor
            ("predictor", PREDICTOR_TOPICS),
        ):
            rule_id = f"{station}-{role}-puts"
            rules.append(
                _rule(rule_id, ["put"], ["ingress"], [keys.station_key(station, t) for t in topics])
            )
            policies.append({"id": rule_id, "rules": [rule_id], "subjects": [names[role]]})
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
    if not argv:
        print("usage: python -m services.router.access_control STATION...", file=sys.stderr)
        return 2
    header = "// zenoh access_control of the line, made by services/router/access_control.py\n"
    sys.stdout.write(header + json.dumps(line_access_control(argv), indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
