"""Fuzz of everything the recorder hears: the real service over real zenoh, real MCAP read back.

Random bytes, random JSON, deep nesting, huge documents and messages with a
field out of bounds go to every message key under ``boltwatch/st1/`` of a
live recorder (:class:`tests.support.fuzz.targets.RecorderTarget`), and queries with
random parameters and payloads to its ``wear`` queryable. Each refused
payload is counted (``RecorderStats.bad_payloads``) and found again, byte for
byte and in order, on its key's raw channel of the MCAP files; the log holds
no traceback and no line per payload: the first refusal at once, then at most
one line per ``INTERVAL_S`` (10 s) saying how many it stands for (one line when
the fuzz is quick, one every 10 s of it on a loaded machine, where it takes a
minute and more); afterwards a good run is recorded and the wear query answers.
The long run: ``tests/benchmarks/fuzz_services.py``.
"""

from __future__ import annotations

import itertools
import re
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shared.runtime.log_limit import INTERVAL_S
from tests.support.fuzz.property import fuzz
from tests.support.fuzz.rules import RECORDER
from tests.support.fuzz.targets import RecorderTarget

EXAMPLES = 100
QUERIES = 15
SUPPRESSED = re.compile(r"\((\d+) more like it since the last line\)$")


def test_nothing_on_the_line_stops_the_recorder_and_nothing_refused_is_lost(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with RecorderTarget(tmp_path) as target:
        count = fuzz(target, RECORDER, EXAMPLES)
        assert count.refused >= EXAMPLES

        @settings(max_examples=QUERIES, deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))  # fmt: skip
        @given(
            parameters=st.text(max_size=60).filter(lambda t: "#" not in t),
            payload=st.none() | st.binary(max_size=2000),
        )
        def query(parameters: str, payload: bytes | None) -> None:
            assert len(target.query_wear(parameters, payload)) == 1  # answered, once

        query()
        target.prove_serving()
        stats = target.running.service.stats(time.time_ns())
        raw, typed = target.read_back()
    (station_stats,) = [s for s in stats if s.station == "st1"]
    assert station_stats.bad_payloads == target.refusals == len(target.refused_payloads)
    assert raw == target.refused_payloads  # each one, byte for byte, in order
    assert len(typed["boltwatch/st1/samples"]) >= 20  # the good run's, and valid extremes
    assert not [r for r in caplog.records if r.exc_info]
    # no line per payload: the first at once, then at most one per INTERVAL_S, each saying
    # how many it stands for (one line when the fuzz takes under INTERVAL_S; on a loaded
    # machine it takes a minute and more, and a line every INTERVAL_S is what it must log)
    refused_lines = [r for r in caplog.records if r.getMessage().startswith("payload on")]
    assert refused_lines
    times_s = [r.created for r in refused_lines]
    assert all(b - a >= INTERVAL_S * 0.999 for a, b in itertools.pairwise(times_s)), times_s
    stood_for = [int(m) for r in refused_lines[1:] for m in SUPPRESSED.findall(r.getMessage())]
    assert len(stood_for) == len(refused_lines) - 1
    assert len(refused_lines) + sum(stood_for) <= target.refusals
