"""Fuzz of the acquisition's decision channel: the real service over real zenoh.

Random bytes, random JSON, deep nesting, huge documents and decisions with a
field out of bounds go to ``boltwatch/st1/decision`` of a live acquisition
(:class:`tests.support.fuzz.targets.AcquisitionTarget`, python-can ``virtual`` bus);
each is counted in ``BusStats.bad_decisions``, none stops the tool, the log
holds no traceback and no line per payload, and a good decision afterwards
still sends its ``StopCommand``. The long run: ``tests/benchmarks/fuzz_services.py``.
"""

from __future__ import annotations

import logging

import pytest

from tests.support.fuzz.property import fuzz
from tests.support.fuzz.rules import ACQUISITION
from tests.support.fuzz.targets import AcquisitionTarget

EXAMPLES = 60


def test_no_decision_payload_stops_the_acquisition_or_the_tool(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO)
    with AcquisitionTarget() as target:
        count = fuzz(target, ACQUISITION, EXAMPLES)
        assert count.refused >= EXAMPLES
        target.prove_serving()
        stats = target.acquisition.stats()
    assert stats.bad_decisions == target.refusals and stats.stop_commands == 1
    assert not [r for r in caplog.records if r.exc_info]
    bad_lines = [r for r in caplog.records if "bad decision payload" in r.getMessage()]
    assert len(bad_lines) == 1, [r.getMessage() for r in bad_lines]
