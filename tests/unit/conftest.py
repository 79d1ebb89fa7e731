"""Fixtures of every unit test folder."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest
import zenoh

from shared.runtime import zenoh_config
from tests.support.live_recorder import free_port


@pytest.fixture(autouse=True)
def logging_restored() -> Iterator[None]:
    """A command run in the test's process (``main([...])``) configures the root logger as
    its process would; each test gets it back as it was, so that no test's log lines
    reach the next one's standard error."""
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    yield
    root.handlers[:] = handlers
    root.setLevel(level)


@pytest.fixture
def sessions() -> Iterator[tuple[zenoh.Session, zenoh.Session]]:
    """Two peer sessions on loopback: (served, feeding); the feeding one connects."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with (
        zenoh.open(zenoh_config("peer", listen=[endpoint])) as served,
        zenoh.open(zenoh_config("peer", connect=[endpoint])) as feeding,
    ):
        yield served, feeding
