"""The retention tests that ask a results store run each on SQLite and on a real PostgreSQL
server (started once for the test run in a temporary folder; skipped with the reason where it
cannot)."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.results import StoreTarget


@pytest.fixture(params=["sqlite", "postgresql"])
def target(request: pytest.FixtureRequest, tmp_path: Path) -> StoreTarget:
    if request.param == "sqlite":
        return StoreTarget(sqlite_path=tmp_path / "recordings" / "results.sqlite")
    return StoreTarget(postgres_url=request.getfixturevalue("postgres_url"))
