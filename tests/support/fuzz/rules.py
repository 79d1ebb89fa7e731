"""What each service refuses beyond the contract's bounds, written down for the fuzz.

Each :class:`ServiceRules` says which extreme (but valid) values the
service's own rules refuse, and which payloads must be refused by those
rules alone (the fuzz adds them to the contract's refusals):

- acquisition (decision): the decision names its own station; its run id
  fits the DBC's 32-bit ``RunId``;
- predictor (samples, tool, part): its own station; ids as wide as the
  station's ``ToolStatus`` signals (RunId 32, ToolId 16, ProgramId 8 bits);
- recorder (everything): the key's station; a message's own time neither
  negative nor more than five minutes ahead of its arrival; a sample's
  torque, angle and force within the sensor range (the shipped DBC's).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from shared.contract import CONTRACT_RANGE, channels
from tests.support.fuzz.payloads import as_json, dumps

AHEAD_NS = 300 * 1_000_000_000  # shared/recordings/received.py: MAX_AHEAD_S
HOUR_NS = 3_600_000_000_000
RUN_ID_MAX = 2**32 - 1
#: what the station's DBC carries (ToolStatus): the predictor narrows ids to it
CAN_IDS = {"run_id": RUN_ID_MAX, "tool_id": 2**16 - 1, "program_id": 2**8 - 1}
MEASURED = {
    "torque_nm": CONTRACT_RANGE.torque_nm,
    "angle_deg": CONTRACT_RANGE.angle_deg,
    "force_n": CONTRACT_RANGE.force_n,
}


@dataclass(frozen=True)
class ServiceRules:
    #: (topic, field, value) -> whether the service refuses a message with that value
    refuses_extreme: Callable[[str, str, Any], bool]
    #: (topic, a valid message) -> payloads only the service's own rules refuse
    extra_refused: Callable[[str, Any], list[bytes]]


def _acquisition_refuses(_topic: str, field: str, value: Any) -> bool:
    if field == "run_id":
        return not 0 <= value <= RUN_ID_MAX
    return field == "station" and value != "st1"


def _acquisition_extra(_topic: str, message: Any) -> list[bytes]:
    fields = as_json(message)
    return [dumps({**fields, "run_id": RUN_ID_MAX + 1}), dumps({**fields, "station": "st2"})]


def _predictor_refuses(topic: str, field: str, value: Any) -> bool:
    if field == "station":
        return value != "pt1"
    if field in CAN_IDS and (topic == channels.TOOL.topic or field == "run_id"):
        return not 0 <= value <= CAN_IDS[field]
    return False


def _predictor_extra(topic: str, message: Any) -> list[bytes]:
    fields = as_json(message)
    wider: dict[str, int] = {
        channels.SAMPLES.topic: {"run_id": 2**32},
        channels.TOOL.topic: {"tool_id": 2**16, "program_id": 256},
    }.get(topic, {})
    others = [dumps({**fields, name: value}) for name, value in wider.items()]
    return [dumps({**fields, "station": "pt2"}), *others]


def _publish_time_field(topic: str) -> str:
    return "ended_ns" if topic == channels.RUNS.topic else "time_ns"


def _recorder_refuses(topic: str, field: str, value: Any) -> bool:
    if field == "station":
        return value != "st1"
    if field == _publish_time_field(topic):  # WearAlert's time_ns may be negative by contract
        return bool(value < 0 or value > time.time_ns() + AHEAD_NS)
    if topic == channels.SAMPLES.topic and field in MEASURED and value is not None:
        low, high = MEASURED[field]
        return math.isnan(value) or not low <= value <= high
    return False


def _recorder_extra(topic: str, message: Any) -> list[bytes]:
    fields = as_json(message)
    ahead = {_publish_time_field(topic): time.time_ns() + HOUR_NS}
    extra = [dumps({**fields, **ahead}), dumps({**fields, "station": "st2"})]
    if topic == channels.SAMPLES.topic:
        extra += [dumps({**fields, "torque_nm": 1e6}), dumps({**fields, "force_n": -1e12})]
    if topic == channels.SAMPLE_BATCHES.topic:  # one sample the recorder refuses refuses the batch
        *good, last = fields["samples"]
        for change in (
            {"torque_nm": 1e6},
            {"station": "st2"},
            {"time_ns": time.time_ns() + HOUR_NS},
        ):
            extra.append(dumps({**fields, "samples": [*good, {**last, **change}]}))
    return extra


ACQUISITION = ServiceRules(_acquisition_refuses, _acquisition_extra)
PREDICTOR = ServiceRules(_predictor_refuses, _predictor_extra)
RECORDER = ServiceRules(_recorder_refuses, _recorder_extra)
