"""The throwaway PostgreSQL server and its fixtures, against the real server."""

from __future__ import annotations

import socket
from pathlib import Path

import psycopg
import pytest

from tests.support.postgres_server import (
    PostgresServer,
    PostgresUnavailableError,
    start_postgres_server,
)


def accepts(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=2.0).close()
    except ConnectionRefusedError:
        return False
    return True


def test_psycopg_connects_to_the_server_database(postgres_server: PostgresServer) -> None:
    with psycopg.connect(postgres_server.url) as connection:
        row = connection.execute(
            "SELECT current_database(), current_setting('server_encoding'), "
            "current_setting('fsync')"
        ).fetchone()
    assert row == ("boltwatch", "UTF8", "off")


@pytest.mark.parametrize("turn", [1, 2])
def test_each_test_gets_an_empty_database_of_its_own(postgres_url: str, turn: int) -> None:
    # The same test twice on one server: a shared database would already hold the table.
    with psycopg.connect(postgres_url) as connection:
        connection.execute("CREATE TABLE seen (turn integer)")
        connection.execute("INSERT INTO seen VALUES (%s)", (turn,))
        assert connection.execute("SELECT turn FROM seen").fetchall() == [(turn,)]
        name = connection.execute("SELECT current_database()").fetchone()
    assert name is not None
    assert name[0].startswith("test_")


def test_a_database_left_connected_is_a_failure(postgres_server: PostgresServer) -> None:
    # DROP DATABASE waits 5 s for the connection to go before it refuses.
    url = postgres_server.create_database("left_connected")
    with psycopg.connect(url), pytest.raises(AssertionError, match="connection open"):
        postgres_server.drop_database("left_connected")
    postgres_server.drop_database("left_connected")


def test_stop_ends_the_server_and_start_brings_back_its_rows(
    own_postgres_server: PostgresServer,
) -> None:
    with psycopg.connect(own_postgres_server.url, autocommit=True) as connection:
        connection.execute("CREATE TABLE kept AS SELECT 7 AS value")
    assert accepts(own_postgres_server.port)

    own_postgres_server.stop()
    assert not accepts(own_postgres_server.port)
    assert not (own_postgres_server.data / "postmaster.pid").exists()
    own_postgres_server.stop()  # safe twice

    own_postgres_server.start()
    with psycopg.connect(own_postgres_server.url) as connection:
        assert connection.execute("SELECT value FROM kept").fetchall() == [(7,)]


def test_kill_cuts_off_its_clients(own_postgres_server: PostgresServer) -> None:
    with psycopg.connect(own_postgres_server.url) as connection:
        own_postgres_server.kill()
        with pytest.raises(psycopg.OperationalError):
            connection.execute("SELECT 1")
    assert not accepts(own_postgres_server.port)


def test_close_removes_the_folder(own_postgres_server: PostgresServer) -> None:
    own_postgres_server.close()
    assert not own_postgres_server.folder.exists()
    own_postgres_server.close()  # safe twice


def test_settings_given_replace_the_test_servers() -> None:
    try:
        server = start_postgres_server(settings={"fsync": "on", "shared_buffers": "'32MB'"})
    except PostgresUnavailableError as err:
        pytest.skip(str(err))
    with server, psycopg.connect(server.url) as connection:
        row = connection.execute(
            "SELECT current_setting('fsync'), current_setting('shared_buffers'), "
            "current_setting('synchronous_commit')"
        ).fetchone()
    assert row == ("on", "32MB", "off")


def test_no_programs_is_a_reason_to_skip(tmp_path: Path) -> None:
    with pytest.raises(PostgresUnavailableError, match="install Debian's postgresql package"):
        start_postgres_server(folders=[tmp_path])
