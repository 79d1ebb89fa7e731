"""Fixtures of every unit test folder."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import zenoh

from shared.runtime import zenoh_config
from tests.live_recorder import free_port


@pytest.fixture
def sessions() -> Iterator[tuple[zenoh.Session, zenoh.Session]]:
    """Two peer sessions on loopback: (served, feeding); the feeding one connects."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with (
        zenoh.open(zenoh_config("peer", listen=[endpoint])) as served,
        zenoh.open(zenoh_config("peer", connect=[endpoint])) as feeding,
    ):
        yield served, feeding
