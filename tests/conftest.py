"""Fixtures of every test folder: a PostgreSQL server, one per test run."""

from __future__ import annotations

import uuid
from collections.abc import Iterator

import pytest

from tests.support.postgres_server import (
    PostgresServer,
    PostgresUnavailableError,
    start_postgres_server,
)


@pytest.fixture(scope="session")
def postgres_server() -> Iterator[PostgresServer]:
    """A real PostgreSQL server of the whole test run, started on first use; skipped with
    the reason where none can start."""
    try:
        server = start_postgres_server()
    except PostgresUnavailableError as err:
        pytest.skip(str(err))
    with server:
        yield server


@pytest.fixture
def postgres_url(postgres_server: PostgresServer) -> Iterator[str]:
    """The url of a new empty database of the test's own, dropped after it (the test fails
    when it left a connection open)."""
    name = f"test_{uuid.uuid4().hex[:16]}"
    url = postgres_server.create_database(name)
    yield url
    postgres_server.drop_database(name)
