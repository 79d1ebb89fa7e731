"""CPU per sample of decoding on the line's hot paths, in-process, before/after side by side.

Run on demand (not collected by pytest)::

    git worktree add /tmp/before 9ac095d     # the code to compare with
    .venv/bin/python tests/benchmarks/bench_line_decode.py --before /tmp/before [--repeats 7]

- predictor: ``codec.decoder(Sample)`` of the ``--before`` checkout (its
  ``shared/codec.py``) against this one; without ``--before``,
  ``codec.decode`` of this checkout (the general decoder) stands in;
- predictor, per stick-slip event: ``codec.encode`` of a StickSlipEvent and
  an Intensity, of the ``--before`` checkout against this one;
- recorder: :func:`classify` of a sample (the bounded decoder, the time
  window and the station's sensor range), this checkout only.

``time.process_time`` over 100 000 calls of a typical sample payload; the
median of ``--repeats`` and the ratio. The figures against 9ac095d in the
README (classify, and encode as it was before) were taken with copies of
that code, since removed: 9ac095d's own ``bench_line_decode.py`` has them.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.recorder.incoming import (  # noqa: E402
    classify,
)
from shared import codec  # noqa: E402
from shared.messages import Intensity, Prediction, Sample, StickSlipEvent  # noqa: E402

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


def us_per_call(call: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.process_time()
        for _ in range(CALLS):
            call()
        times.append((time.process_time() - start) / CALLS * 1e6)
    return statistics.median(times)


def codec_of_checkout(checkout: Path) -> Any:
    """Another checkout's ``shared/codec.py``, loaded under another module name (what it
    imports comes from this checkout)."""
    spec = importlib.util.spec_from_file_location("codec_before", checkout / "shared/codec.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--before", type=Path, help="a checkout of the code to compare with")
    args = parser.parse_args(argv)
    decode_sample = codec.decoder(Sample)
    decode_before: Callable[[bytes], Any] = functools.partial(codec.decode, Sample)
    encode_before: Callable[[Any], bytes] = codec.encode
    if args.before is not None:
        before = codec_of_checkout(args.before)
        decode_before, encode_before = before.decoder(Sample), before.encode
    log_time_ns = 1712345678123456789 + 1_000_000
    assert decode_sample(PAYLOAD) == decode_before(PAYLOAD)
    assert codec.encode(EVENT) == encode_before(EVENT)
    pairs = {
        "predictor: decode a Sample": (
            lambda: decode_before(PAYLOAD),
            lambda: decode_sample(PAYLOAD),
        ),
        "predictor: encode a StickSlipEvent and its Intensity": (
            lambda: (encode_before(EVENT), encode_before(INTENSITY)),
            lambda: (codec.encode(EVENT), codec.encode(INTENSITY)),
        ),
    }
    for name, (before_call, after_call) in pairs.items():
        before_us = us_per_call(before_call, args.repeats)
        after_us = us_per_call(after_call, args.repeats)
        print(
            f"{name}: before {before_us:.2f} µs, after {after_us:.2f} µs "
            f"(×{after_us / before_us:.2f})",
            flush=True,
        )
    classify_us = us_per_call(lambda: classify(KEY, PAYLOAD, log_time_ns), args.repeats)
    print(f"recorder: classify a Sample: {classify_us:.2f} µs", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
