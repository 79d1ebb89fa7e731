"""Fixtures of every test folder: a PostgreSQL server, one per test run or one of a test's own."""

from __future__ import annotations

import uuid
from collections.abc import Iterator

import pytest

from tests.support.postgres_server import (
    PostgresServer,
    PostgresUnavailableError,
    start_postgres_server,
)


def _started_or_skipped() -> PostgresServer:
    """A real PostgreSQL server started now; the test skipped with the reason where none can."""
    try:
        return start_postgres_server()
    except PostgresUnavailableError as err:
        pytest.skip(str(err))


@pytest.fixture(scope="session")
def postgres_server() -> Iterator[PostgresServer]:
    """A real PostgreSQL server of the whole test run (of each xdist worker under
    ``make test``), started on first use."""
    with _started_or_skipped() as server:
        yield server


@pytest.fixture
def own_postgres_server() -> Iterator[PostgresServer]:
    """A real PostgreSQL server of the test's own, which it may stop and start."""
    with _started_or_skipped() as server:
        yield server


@pytest.fixture
def postgres_url(postgres_server: PostgresServer) -> Iterator[str]:
    """The url of a new empty database of the test's own, dropped after it (the test fails
    when it left a connection open)."""
    name = f"test_{uuid.uuid4().hex[:16]}"
    url = postgres_server.create_database(name)
    yield url
    postgres_server.drop_database(name)
