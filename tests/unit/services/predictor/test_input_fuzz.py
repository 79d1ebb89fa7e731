"""Fuzz of the predictor's channels (samples, tool, part): the real service over real zenoh.

Random bytes, random JSON, deep nesting, huge documents and messages with a
field out of bounds go to ``boltwatch/pt1/samples``, ``/tool`` and ``/part`` of a live
predictor (:class:`tests.support.fuzz.targets.PredictorTarget`); each is counted as
a bad payload (and in PredictorStats), the log holds no traceback and no
line per payload, and a good run afterwards is still decided. The long run:
``tests/benchmarks/fuzz_services.py``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.fuzz.property import fuzz
from tests.support.fuzz.rules import PREDICTOR
from tests.support.fuzz.targets import PredictorTarget

EXAMPLES = 60


def test_no_sample_or_tool_payload_stops_the_predictor(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with PredictorTarget(tmp_path) as target:
        count = fuzz(target, PREDICTOR, EXAMPLES)
        assert count.refused >= EXAMPLES
        target.prove_serving()
        assert target.service.counts["pt1"].bad_payloads == target.refusals
    assert not [r for r in caplog.records if r.exc_info]
    bad_lines = [r for r in caplog.records if "ignored a" in r.getMessage()]
    assert len(bad_lines) == 1, [r.getMessage() for r in bad_lines]
