"""CPU per sample of decoding on the line's hot paths, in-process, before/after side by side.

Run on demand (not collected by pytest)::

    git worktree add /tmp/before 9ac095d     # the code to compare with
    .venv/bin/python tests/benchmarks/bench_line_decode.py --before /tmp/before [--repeats 7]

- predictor: ``codec.decoder(Sample)`` of the ``--before`` checkout (its
  ``shared/codec.py``; at 9ac095d: every field's JSON type checked, no
  bounds) against this one (types, every field's bounds, payload size and
  nesting); without ``--before``, ``codec.decode`` of this checkout (the
  general decoder) stands in;
- recorder: :func:`classify` of a sample as at 9ac095d (the ``--before``
  decoder, no time window, no sensor range) against the current one (the
  bounded decoder, the time window and the station's sensor range);
- predictor, per stick-slip event: ``codec.encode`` of a StickSlipEvent and
  an Intensity as it was (``dataclasses.is_dataclass`` on every field, a
  ``json.dumps`` encoder per call) against the current one.

``time.process_time`` over 100 000 calls of a typical sample payload; the
median of ``--repeats`` and the ratio.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import json
import statistics
import sys
import time
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.recorder.incoming import (  # noqa: E402
    OTHER_STATION,
    Received,
    classify,
)
from shared import channels, codec, keys  # noqa: E402
from shared.errors import InputError  # noqa: E402
from shared.messages import Intensity, Prediction, Sample, StickSlipEvent  # noqa: E402
from shared.sensor_range import SensorRange  # noqa: E402

CALLS = 100_000
PAYLOAD = (
    b'{"station":"st12","run_id":1712345678,"sequence":512,"time_ns":1712345678123456789,'
    b'"torque_nm":123.45678912345,"angle_deg":45.678912345678,"force_n":30123.456789012}'
)
KEY = "boltwatch/st12/samples"
EVENT = StickSlipEvent(
    "st12", 5, 3, 1712345678123456789, 0.5123, 120.5123, 100.2123, 20.3123, 30000.5123,
    500.2123, 0.0512, 19.5123, 1.0123, 2.0123, 3.0123, 0.4123, 1.2123,
    [Prediction(1, 0.5512, 125.0123, 30500.0123), Prediction(2, 0.6012, 130.0123, None)],
)  # fmt: skip
INTENSITY = Intensity("st12", 5, 1712345678123456789, 0.4123, 1.2123)


def to_dict_as_before(message: Any) -> dict[str, Any]:
    """codec.to_dict before this change: is_dataclass on every field."""
    out: dict[str, Any] = {}
    for field in dataclasses.fields(message):
        value = getattr(message, field.name)
        if isinstance(value, list):
            value = [
                to_dict_as_before(item) if dataclasses.is_dataclass(item) else item
                for item in value
            ]
        elif dataclasses.is_dataclass(value):
            value = to_dict_as_before(value)
        out[field.name] = value
    return out


def encode_as_before(message: Any) -> bytes:
    return json.dumps(to_dict_as_before(message), separators=(",", ":")).encode()


def classify_as_before(
    key: str,
    payload: bytes,
    log_time_ns: int,
    sensor_ranges: Mapping[str, SensorRange] | None = None,
) -> Received:
    """classify() two changes ago: codec.decode of every recorded type, no time window
    (bench_line_inbox.py's ``recorder-classify-before``)."""
    try:
        station, topic = keys.split_key(key)
    except ValueError:
        return Received(key, OTHER_STATION, None, None, payload, log_time_ns, log_time_ns)
    channel = channels.by_topic(topic)
    if channel is None:
        return Received(key, station, None, None, payload, log_time_ns, log_time_ns)
    schema_name = channel.schema_name
    try:
        message: Any = codec.decode(channel.message_type, payload)
    except InputError:
        return Received(key, station, schema_name, None, payload, log_time_ns, log_time_ns)
    own_time = getattr(message, "time_ns", getattr(message, "ended_ns", None))
    publish_time_ns = own_time if isinstance(own_time, int) else log_time_ns
    return Received(key, station, schema_name, message, payload, log_time_ns, publish_time_ns)


def classify_sample_with(
    decode_sample: Callable[[bytes], Any],
) -> Callable[[str, bytes, int], Received]:
    """classify() of a sample as at 9ac095d, with ``decode_sample`` (no window, no range)."""

    def classify_sample(key: str, payload: bytes, log_time_ns: int) -> Received:
        station, _topic = keys.split_key(key)
        try:
            message = decode_sample(payload)
        except InputError:
            return Received(
                key, station, channels.SAMPLES.schema_name, None, payload, log_time_ns, 0
            )
        return Received(
            key,
            station,
            channels.SAMPLES.schema_name,
            message,
            payload,
            log_time_ns,
            message.time_ns,
        )

    return classify_sample


def us_per_call(call: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.process_time()
        for _ in range(CALLS):
            call()
        times.append((time.process_time() - start) / CALLS * 1e6)
    return statistics.median(times)


def decoder_of_checkout(checkout: Path) -> Callable[[bytes], Any]:
    """``codec.decoder(Sample)`` of another checkout's ``shared/codec.py`` (loaded under
    another module name; what it imports comes from this checkout)."""
    spec = importlib.util.spec_from_file_location("codec_before", checkout / "shared/codec.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return typing.cast(Callable[[bytes], Any], module.decoder(Sample))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--before", type=Path, help="a checkout of the code to compare with")
    args = parser.parse_args(argv)
    decode_sample = codec.decoder(Sample)
    decode_before: Callable[[bytes], Any] = (
        decoder_of_checkout(args.before)
        if args.before is not None
        else lambda payload: codec.decode(Sample, payload)
    )
    log_time_ns = 1712345678123456789 + 1_000_000
    classify_before = classify_sample_with(decode_before)
    assert decode_sample(PAYLOAD) == decode_before(PAYLOAD)
    assert classify(KEY, PAYLOAD, log_time_ns) == classify_before(KEY, PAYLOAD, log_time_ns)
    assert codec.encode(EVENT) == encode_as_before(EVENT)
    pairs = {
        "predictor: decode a Sample": (
            lambda: decode_before(PAYLOAD),
            lambda: decode_sample(PAYLOAD),
        ),
        "recorder: classify a Sample": (
            lambda: classify_before(KEY, PAYLOAD, log_time_ns),
            lambda: classify(KEY, PAYLOAD, log_time_ns),
        ),
        "predictor: encode a StickSlipEvent and its Intensity": (
            lambda: (encode_as_before(EVENT), encode_as_before(INTENSITY)),
            lambda: (codec.encode(EVENT), codec.encode(INTENSITY)),
        ),
    }
    for name, (before, after) in pairs.items():
        before_us = us_per_call(before, args.repeats)
        after_us = us_per_call(after, args.repeats)
        print(
            f"{name}: before {before_us:.2f} µs, after {after_us:.2f} µs "
            f"(×{after_us / before_us:.2f})",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
