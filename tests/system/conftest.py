"""Fixtures of the system tests."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.support.router_process import router_process


@pytest.fixture
def router(tmp_path: Path) -> Iterator[str]:
    """A ``boltwatch serve router`` process; yields its endpoint once it accepts clients."""
    with router_process(tmp_path) as endpoint:
        yield endpoint
