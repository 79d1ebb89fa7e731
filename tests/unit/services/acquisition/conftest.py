"""The acquisition's tests: a tool's and a station's end of one python-can virtual bus."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import can
import pytest

_channels = itertools.count()


@pytest.fixture
def buses() -> Iterator[tuple[can.BusABC, can.BusABC]]:
    """(the tool's end, the station's end) of a virtual bus of its own."""
    channel = f"acq-test-{next(_channels)}"
    with (
        can.Bus(interface="virtual", channel=channel) as tool,
        can.Bus(interface="virtual", channel=channel) as station,
    ):
        yield tool, station
