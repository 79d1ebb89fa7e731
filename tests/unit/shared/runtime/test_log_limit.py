"""RateLimitedLog: a flood of alike faults is one line, then one per interval with a count."""

from __future__ import annotations

import logging

import pytest

from shared.runtime import RateLimitedLog


def test_the_first_at_once_then_one_line_per_interval_counting_the_rest(
    caplog: pytest.LogCaptureFixture,
) -> None:
    now = [100.0]
    log = RateLimitedLog(logging.getLogger("flood"), logging.ERROR, 10.0, lambda: now[0])
    for n in range(1000):  # a thousand bad payloads within a second
        now[0] += 0.001
        log("bad payload #%d", n + 1)
    now[0] += 10.0
    log("bad payload #%d", 1001)
    assert [(r.levelno, r.getMessage()) for r in caplog.records] == [
        (logging.ERROR, "bad payload #1 (logged once, then at most every 10 s)"),
        (logging.ERROR, "bad payload #1001 (999 more like it since the last line)"),
    ]
    assert log.suppressed == 0
