"""The services' fuzz for longer: the property of the tests, for minutes instead of seconds.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/fuzz_services.py --minutes 10

The same targets, payloads and property as ``tests/unit/*/test_*_fuzz.py``
(:mod:`tests.support.fuzz`): each live service (acquisition, predictor, recorder)
gets a third of the time, in rounds of ``--examples`` hypothesis examples,
each new round drawing new payloads; then it must still serve (a good
decision stops the tool, a good run is decided, a good run is recorded), and
the recorder's MCAP must hold every refused payload byte for byte. Prints per
service the examples, the payloads refused and taken, what the service
counted, its log lines and the wall time; exit status 1 on the first failure
(with hypothesis's smallest failing example).
"""

from __future__ import annotations

import argparse
import logging
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from tests.support.fuzz.property import FuzzCount, fuzz
from tests.support.fuzz.rules import ACQUISITION, PREDICTOR, RECORDER, ServiceRules
from tests.support.fuzz.targets import AcquisitionTarget, PredictorTarget, RecorderTarget


class CountingHandler(logging.Handler):
    """Counts the log records of WARNING and above, and those with a traceback."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines = 0
        self.tracebacks = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.lines += 1
        self.tracebacks += record.exc_info is not None


def fuzz_for(
    name: str, make: Callable[[Path], Any], rules: ServiceRules, seconds: float, examples: int
) -> bool:
    handler = CountingHandler()
    logging.getLogger().addHandler(handler)
    total = FuzzCount()
    started = time.monotonic()
    try:
        with tempfile.TemporaryDirectory() as folder, make(Path(folder)) as target:
            while time.monotonic() - started < seconds:
                count = fuzz(target, rules, examples)
                total.examples += count.examples
                total.refused += count.refused
                total.valid += count.valid
            target.prove_serving()
            refused = target.refused()
            if isinstance(target, RecorderTarget):
                raw, _ = target.read_back()
                assert raw == target.refused_payloads, "a refused payload is missing from MCAP"
    except Exception as err:  # hypothesis has printed its smallest failing example
        print(f"{name}: FAILED after {time.monotonic() - started:.0f} s: {err!r}", flush=True)
        return False
    finally:
        logging.getLogger().removeHandler(handler)
    print(
        f"{name}: {total.examples} examples in {time.monotonic() - started:.0f} s, "
        f"{total.refused} payloads to refuse ({refused} counted), {total.valid} extreme "
        f"but valid taken; still serving; {handler.lines} log lines (WARNING and above), "
        f"{handler.tracebacks} tracebacks",
        flush=True,
    )
    return handler.tracebacks == 0 and refused == total.refused


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="all three services")
    parser.add_argument("--examples", type=int, default=200, help="per hypothesis round")
    args = parser.parse_args(argv)
    logging.getLogger().setLevel(logging.WARNING)  # counted (CountingHandler), not printed
    seconds = args.minutes * 60 / 3
    targets: list[tuple[str, Callable[[Path], Any], ServiceRules]] = [
        ("acquisition (decision)", lambda _folder: AcquisitionTarget(), ACQUISITION),
        ("predictor (samples, tool)", PredictorTarget, PREDICTOR),
        ("recorder (every message key)", RecorderTarget, RECORDER),
    ]
    ok = [fuzz_for(name, make, rules, seconds, args.examples) for name, make, rules in targets]
    return 0 if all(ok) else 1


if __name__ == "__main__":
    sys.exit(main())
