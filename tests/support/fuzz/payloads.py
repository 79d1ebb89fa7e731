"""Hypothesis strategies of hostile payloads for the channels of the live services.

Two kinds, because the property checked differs:

- :func:`refused` payloads must each be refused and counted by the service
  that receives them: random bytes, random JSON that is no message, deep
  nesting (up to 100 000 levels), documents beyond the size bound, and a
  well-formed message with one field out of its declared bounds (±2**63,
  10**30, -1, NaN, infinities, 10**400, huge strings, wrong enums, wrong
  types, an unknown or a missing field), plus what the service's own rules
  refuse (``extra_refused``: another station, ids wider than a CAN signal, a
  time an hour ahead of its arrival, a value outside the sensor range);
- :func:`extremes` payloads are valid messages at the edges of their bounds
  (1e308, 2**63 - 1, 0, 64-character station ids, NaN where a measured value
  may be NaN): a service must survive them, and takes them unless its own
  rules refuse them (the caller says which, from the field and the value).

Which values a field refuses is read from its declared bounds
(:mod:`shared.contract.message_fields`), never from the decoder under test.
"""

from __future__ import annotations

import dataclasses
import json
import math
import types
import typing
from collections.abc import Callable
from typing import Any

from hypothesis import strategies as st

from services.recorder.wear_watch import WearAlert
from shared.contract import (
    DEFAULT_FLOAT,
    DEFAULT_INT,
    DEFAULT_TEXT,
    FLOAT_MAX,
    MAX_PAYLOAD_BYTES,
    AlertAck,
    BridgeStats,
    BusStats,
    ControllerAlarm,
    ControllerFunction,
    ControllerResult,
    ControllerStep,
    CycleResult,
    CycleSpindle,
    Intensity,
    JudgedFigure,
    NumberRange,
    PartScan,
    Prediction,
    PredictorStats,
    QualityAlert,
    RecorderStats,
    ResultStep,
    RunSummary,
    Sample,
    SampleBatch,
    SeqRange,
    SpoolAck,
    SpoolStats,
    StageDecision,
    StickSlipEvent,
    StopDecision,
    TextRange,
    TighteningResult,
    ToolData,
    ToolState,
    WearForecast,
    to_dict,
)

#: depths of [[[...]]]: past the parser's recursion limit, within and beyond the size bound
DEPTHS = (1_500, 30_000, 100_000)


def template(topic: str, station: str, now_ns: int, run_id: int = 1) -> Any:
    """A valid message of ``topic`` (a key below ``boltwatch/<station>/``), stamped ``now_ns``."""
    made: dict[str, Callable[[], Any]] = {
        "samples": lambda: Sample(station, run_id, 5, now_ns, 10.0, 1.0, 20_000.0),
        "sample_batches": lambda: SampleBatch(
            station,
            now_ns,
            [
                Sample(station, run_id, n, now_ns - 1_000_000 * (2 - n), 10.0, 1.0, 2e4)
                for n in range(3)
            ],
        ),
        "tool": lambda: ToolState(station, run_id, 3, 1, "done", now_ns),
        "bus": lambda: BusStats(station, now_ns, 10, 5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        "events": lambda: StickSlipEvent(
            station,
            run_id,
            1,
            now_ns,
            0.1,
            50.0,
            45.0,
            5.0,
            20_000.0,
            100.0,
            0.02,
            50.0,
            1.0,
            2.0,
            3.0,
            0.5,
            0.5,
            [Prediction(1, 0.12, 55.0, 20_500.0)],
        ),
        "intensity": lambda: Intensity(station, run_id, now_ns, 0.5, 0.5),
        "decision": lambda: StopDecision(
            station, run_id, now_ns, 0.1, "plateau_closest", "", 50.0, 2e4, 2.1e4, now_ns
        ),
        "stage": lambda: StageDecision(
            station, run_id, now_ns, 1.2, "final", "near_target", "", 190.0, 0, now_ns
        ),
        "runs": lambda: RunSummary(
            station,
            run_id,
            3,
            1,
            "done",
            3e4,
            None,
            3e4,
            50.0,
            0.1,
            1,
            None,
            0.5,
            10,
            now_ns - 1_000_000_000,
            now_ns,
        ),
        "results": lambda: TighteningResult(
            station=station,
            tightening_id=run_id,
            run_id=run_id,
            tool_id=3,
            program_id=1,
            program_name="M14",
            time_ns=now_ns,
            part_id=None,
            batch_counter=None,
            final_torque_nm=JudgedFigure(50.0, 40.0, 60.0, "ok"),
            final_angle_deg=JudgedFigure(None, None, None, "not_judged"),
            final_force_n=JudgedFigure(3e4, 3.1e4, None, "low"),
            result="NOK",
            nok_reasons="preload low",
            stop_reason="plateau_closest",
            events=1,
            process_intensity=0.5,
            source="predictor",
            steps=[ResultStep("Tightening", "TF Torque", 1.4, 1.41, "OK")],
        ),
        "cycles": lambda: CycleResult(
            station=station,
            sync_id=run_id,
            time_ns=now_ns,
            part_id=f"{station}-P{run_id:06d}",
            program_id=1,
            result="NOK",
            nok_reasons="spindle 2 no result",
            source="predictor",
            spindles=[CycleSpindle(1, run_id, "OK"), CycleSpindle(2, None, None)],
        ),
        "recorder": lambda: RecorderStats(station, now_ns, 1, None, None, 0, None, True),
        "predictor": lambda: PredictorStats(station, now_ns, now_ns, 0, 0, 0, 0, 0),
        "controller": lambda: ControllerResult(
            station,
            run_id,
            955000040,
            9,
            now_ns,
            "OK",
            "1",
            "part",
            "Nm",
            3,
            None,
            None,
            None,
            None,
            None,
            None,
            None,
            None,
            [ControllerStep("Finding", "OK", "1", 9, [ControllerFunction("TF Angle", 1.0, 1.5)])],
        ),
        "wear/alert": lambda: WearAlert(station, 3, now_ns, 2e9, 1e9, 4, None),
        "wear/forecast": lambda: WearForecast(
            station=station,
            tool_id=3,
            time_ns=now_ns,
            horizon_days=7.0,
            due_ns=now_ns + 86_400_000_000_000,
            early_ns=now_ns + 43_200_000_000_000,
            late_ns=None,
            production_days=1.0,
            runs_left=400,
            intensity_since_service=9e8,
            threshold=1e9,
            intensity_per_day=1e8,
            runs_since_service=4_000,
            last_service_ns=None,
            service_by_ns=now_ns + 28_800_000_000_000,
        ),
        "quality/alert": lambda: QualityAlert(
            station, 1, now_ns, "cpk_low", "preload", 0.9, 1.33, 50, True, "program 1: low"
        ),
        "tool_data": lambda: ToolData(
            station=station,
            tool_id=3,
            time_ns=now_ns,
            tool_serial="B1234567",
            controller_serial="C98765",
            tightenings=12_345,
            tightenings_since_service=345,
            last_calibration_ns=now_ns - 86_400_000_000_000,
            last_service_ns=None,
            calibration_value_nm=50.5,
            tool_type="01",
            tool_model=None,
            controller_software="Power Focus 6000 3.1",
        ),
        "alarms": lambda: ControllerAlarm(
            station, now_ns, now_ns, "E404", "raised", True, False, True, "tool overheated"
        ),
        "openprotocol": lambda: BridgeStats(
            station=station,
            time_ns=now_ns,
            started_ns=now_ns - 60_000_000_000,
            controller="192.0.2.10:4545",
            connected=True,
            result_revision=2,
            connects=1,
            link_drops=0,
            keep_alives_sent=6,
            results=run_id,
            results_filled=0,
            repeated_results=0,
            traces=run_id,
            traces_without_result=0,
            garbage_bytes=0,
            bad_messages=0,
            refused_values=0,
            controller_errors=0,
            last_tightening_id=run_id,
            last_error=None,
        ),
        "spool": lambda: SpoolStats(
            station=station,
            source="acquisition",
            spool_id=7,
            time_ns=now_ns,
            messages=40,
            samples=1500,
            runs=2,
            bytes=2_000_000,
            max_bytes=4_000_000_000,
            oldest_seq=run_id,
            head_seq=run_id + 40,
            oldest_run_id=run_id,
            oldest_ns=now_ns - 2_000_000_000,
            resent=12,
            resend_rate=0.0,
            dropped_samples=0,
            dropped_messages=0,
            acknowledged_ns=now_ns - 500_000_000,
        ),
        "spool/ack": lambda: SpoolAck(
            station=station,
            source="acquisition",
            spool_id=7,
            time_ns=now_ns,
            through=run_id,
            ranges=[SeqRange(run_id + 5, run_id + 9)],
        ),
        "part": lambda: PartScan(station, f"{station}-P{run_id:06d}", now_ns),
        "alert/ack": lambda: AlertAck(
            station=station,
            time_ns=now_ns,
            action="acknowledged",
            source="wear",
            condition="wear/7",
            condition_name="Wear of tool 7",
            alert_time_ns=now_ns - 2_000_000_000,
            active=True,
            user="scada",
            client="urn:example:scada",
            comment="socket changed at the next stop",
        ),
    }
    return made[topic]()


def as_json(message: Any) -> dict[str, Any]:
    return to_dict(message)


def dumps(value: Any) -> bytes:
    return json.dumps(value, separators=(",", ":")).encode()


# -- what a field refuses, from its declared bounds ------------------------------------


def _field_kinds(message_type: type) -> dict[str, tuple[Any, ...]]:
    """name -> (base types, bound or None, optional, enum values or None, nested type)."""
    hints = typing.get_type_hints(message_type, include_extras=True)
    out: dict[str, tuple[Any, ...]] = {}
    for field in dataclasses.fields(message_type):
        hint = hints[field.name]
        args = (
            typing.get_args(hint)
            if typing.get_origin(hint) in (typing.Union, types.UnionType)
            else (hint,)
        )
        optional = type(None) in args
        bases: list[Any] = []
        bound, enum, nested = None, None, None
        for option in args:
            if option is type(None):
                continue
            base = option
            if typing.get_origin(option) is typing.Annotated:
                base, *extras = typing.get_args(option)
                bound = next((e for e in extras if isinstance(e, NumberRange | TextRange)), None)
            if typing.get_origin(base) is typing.Literal:
                enum = typing.get_args(base)
                bases.append(str)
            elif typing.get_origin(base) is list:
                nested = typing.get_args(base)[0]
                bases.append(list)
            else:
                bases.append(base)
        out[field.name] = (tuple(bases), bound, optional, enum, nested)
    return out


def refused_values(message_type: type, name: str) -> list[Any]:
    """Values the declared bounds of ``message_type.name`` refuse."""
    bases, bound, optional, enum, nested = _field_kinds(message_type)[name]
    values: list[Any] = [[1], {"a": 1}]
    if not optional:
        values.append(None)
    if enum is not None:
        return [*values, "bogus", "", "RUNNING", 1, True, "x" * 5000]
    if nested is not None:
        return [*values[1:], "x", [1], [{"bad": 1}], [None]]
    base = bases[0]
    if base is bool:
        return [*values, 1, 0, "true"]
    if base is int:
        number = bound if isinstance(bound, NumberRange) else DEFAULT_INT
        low, high = int(number.low), int(number.high)
        return [*values, low - 1, high + 1, 10**30, -(2**64), 1e30, -1e30, math.nan,
                math.inf, "1", True, 1.5]  # fmt: skip
    if base is float:
        number = bound if isinstance(bound, NumberRange) else DEFAULT_FLOAT
        beyond = [10**400, -(10**400), "1.5", True]
        return [*values, *beyond] if number.nan_ok else [*values, *beyond, math.nan, math.inf]
    text = bound if isinstance(bound, TextRange) else DEFAULT_TEXT
    wrong = [*values, 1, 1.5, True, "x" * (text.max_chars + 1)]
    if text.pattern is not None:
        pattern = text.pattern
        candidates = ["", "st 1", "st1\n", "stü", "a/b", "*", "x" * 65, " x", "x ", "a\x1db"]
        wrong += [c for c in candidates if pattern.fullmatch(c) is None or len(c) > text.max_chars]
    return wrong


def extreme_values(message_type: type, name: str) -> list[Any]:
    """Values at the edges of what ``message_type.name`` takes (valid)."""
    bases, bound, optional, enum, nested = _field_kinds(message_type)[name]
    values: list[Any] = [None] if optional else []
    if enum is not None or nested is not None:
        return values
    base = bases[0]
    if base is int:
        number = bound if isinstance(bound, NumberRange) else DEFAULT_INT
        low, high = int(number.low), int(number.high)
        return [*values, low, high, *([0] if low <= 0 <= high else [])]
    if base is float:
        number = bound if isinstance(bound, NumberRange) else DEFAULT_FLOAT
        edges = [FLOAT_MAX, -FLOAT_MAX, 1e308, 5e-324, 0.0, -0.0, float(number.low)]
        edges = [e for e in [*edges, float(number.high)] if number.low <= e <= number.high]
        return [*values, *edges, math.nan, math.inf] if number.nan_ok else [*values, *edges]
    if base is str:
        text = bound if isinstance(bound, TextRange) else DEFAULT_TEXT
        return [*values, "z" * min(text.max_chars, 64), "_", "-"]
    return values


# -- strategies ------------------------------------------------------------------------


def random_json() -> st.SearchStrategy[bytes]:
    """JSON documents of any shape (objects with message-like keys among them)."""
    leaves = (
        st.none()
        | st.booleans()
        | st.integers(-(2**70), 2**70)
        | st.floats(allow_nan=True, allow_infinity=True)
        | st.text(max_size=40)
    )
    keys = st.sampled_from(["station", "run_id", "time_ns", "state", "reason", "x"]) | st.text()
    documents = st.recursive(
        leaves,
        lambda inner: st.lists(inner, max_size=6) | st.dictionaries(keys, inner, max_size=8),
        max_leaves=30,
    )
    return documents.map(dumps)


def deep_nesting() -> st.SearchStrategy[bytes]:
    def build(depth: int, kind: int) -> bytes:
        if kind == 0:
            return b"[" * depth + b"]" * depth
        if kind == 1:
            return b'{"a":' * depth + b"1" + b"}" * depth
        return b'{"station":' + b"[" * depth  # deep and cut short

    return st.builds(build, st.sampled_from(DEPTHS), st.integers(0, 2))


def huge_documents() -> st.SearchStrategy[bytes]:
    """Beyond the size bound, and just within it."""
    return st.sampled_from(
        [
            dumps(list(range(20_000))),
            dumps({"station": "s" * (MAX_PAYLOAD_BYTES + 10)}),
            b" " * (MAX_PAYLOAD_BYTES + 1),
            dumps({"x": "y" * (MAX_PAYLOAD_BYTES - 20)}),
        ]
    )


def out_of_bounds(message: Any) -> st.SearchStrategy[bytes]:
    """``message`` with one field refused by its bounds, an unknown field or a missing one."""
    fields = as_json(message)
    names = [f.name for f in dataclasses.fields(message)]

    def one_field(name: str) -> st.SearchStrategy[bytes]:
        return st.sampled_from(refused_values(type(message), name)).map(
            lambda value: dumps({**fields, name: value})
        )

    changed = st.sampled_from(names).flatmap(one_field)
    unknown = st.just(dumps({**fields, "extra_field": 1}))
    required = [n for n in names if not _has_default(type(message), n)]
    missing = st.sampled_from(required).map(
        lambda name: dumps({k: v for k, v in fields.items() if k != name})
    )
    return changed | unknown | missing


def _has_default(message_type: type, name: str) -> bool:
    field = next(f for f in dataclasses.fields(message_type) if f.name == name)
    return not (
        field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING
    )


def refused(message: Any, extra_refused: list[bytes] | None = None) -> st.SearchStrategy[bytes]:
    """Payloads a service receiving ``message``'s channel must refuse and count."""
    kinds = [
        st.binary(max_size=200).filter(_not_an_object),
        random_json().filter(_not_an_object),
        deep_nesting(),
        huge_documents(),
        out_of_bounds(message),
    ]
    if extra_refused:
        kinds.append(st.sampled_from(extra_refused))
    return st.one_of(kinds)


def _not_an_object(payload: bytes) -> bool:
    """Random bytes or JSON that is no JSON object cannot be a message (one that is an
    object could only be one with exactly the message's field names: kept out anyway)."""
    try:
        return not isinstance(json.loads(payload), dict)
    except (ValueError, RecursionError):
        return True


#: (field name, its value, the payload) of an extreme message
Extreme = tuple[str, Any, bytes]


def extremes(message: Any) -> st.SearchStrategy[Extreme]:
    """``message`` with one field at an edge of its bounds (valid by the contract; a
    service's own rules may refuse it: the caller decides from the field and value)."""
    fields = as_json(message)
    candidates = [
        (f.name, value)
        for f in dataclasses.fields(message)
        for value in extreme_values(type(message), f.name)
    ]
    return st.sampled_from(candidates).map(
        lambda pair: (pair[0], pair[1], dumps({**fields, pair[0]: pair[1]}))
    )
