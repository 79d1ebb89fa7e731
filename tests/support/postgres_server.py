"""A throwaway PostgreSQL server for a test: its own folder, port and databases.

:func:`start_postgres_server` finds the server's programs (on ``PATH``, else in Debian's
``/usr/lib/postgresql/<version>/bin``, newest first), runs ``initdb`` into a new
temporary folder and starts the server with ``pg_ctl -w`` on 127.0.0.1 and a unix socket
in that folder. It is a test server: trust authentication, ``fsync`` off, small buffers
(:data:`SETTINGS`; a benchmark passes its own over them, e.g. ``fsync`` on).

``initdb`` refuses to run as root: as root, the programs run as Debian's ``postgres``
user and the folder is handed to it. When the server cannot start (no programs, no
``postgres`` user, initdb or the start fails), :class:`PostgresUnavailableError` says why,
with the tail of the server's log, so that a fixture can skip with the reason.
"""

from __future__ import annotations

import os
import pwd
import re
import shutil
import subprocess
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path
from types import TracebackType
from typing import Literal

import psycopg
from psycopg import sql

from tests.support.live_recorder import free_port

DEBIAN_BINARIES = Path("/usr/lib/postgresql")
PROGRAMS = ("initdb", "pg_ctl", "postgres")
OS_USER_AS_ROOT = "postgres"  # Debian's postgresql package makes this user
SUPERUSER = "postgres"  # the database role the tests connect as
DATABASE = "boltwatch"
COMMAND_TIMEOUT_S = 60.0
LOG_TAIL_LINES = 20

# A server for tests: nothing needs to survive a crash of the machine.
SETTINGS = {
    "listen_addresses": "'127.0.0.1'",
    "fsync": "off",
    "synchronous_commit": "off",
    "full_page_writes": "off",
    "shared_buffers": "'16MB'",
    "max_connections": "50",
}


class PostgresUnavailableError(Exception):
    """No PostgreSQL server could be started here; the message says why."""


def binary_folders() -> list[Path]:
    """Folders that may hold the server's programs: ``initdb``'s on ``PATH``, then
    Debian's, newest version first."""
    folders = []
    if initdb := shutil.which("initdb"):
        folders.append(Path(initdb).parent)

    def version(folder: Path) -> tuple[int, ...]:
        return tuple(int(part) for part in re.findall(r"\d+", folder.parent.name))

    folders += sorted(DEBIAN_BINARIES.glob("*/bin"), key=version, reverse=True)
    return folders


def find_binaries(folders: Iterable[Path]) -> Path:
    """The first of ``folders`` with every program of :data:`PROGRAMS`."""
    folders = list(folders)
    for folder in folders:
        if all(os.access(folder / program, os.X_OK) for program in PROGRAMS):
            return folder
    searched = ", ".join(str(folder) for folder in folders) or f"PATH and {DEBIAN_BINARIES}/*/bin"
    raise PostgresUnavailableError(
        f"no PostgreSQL server programs ({', '.join(PROGRAMS)}) in {searched}: "
        "install Debian's postgresql package"
    )


def tail(text: str, lines: int = LOG_TAIL_LINES) -> str:
    """The last ``lines`` lines of ``text``."""
    return "\n".join(text.strip().splitlines()[-lines:])


class PostgresServer:
    """A PostgreSQL server in ``folder`` (its data, log and unix socket), listening on
    127.0.0.1:``port``. :func:`start_postgres_server` makes and starts one; ``close()``
    stops it and removes the folder. ``stop()`` and ``close()`` are safe to call twice."""

    def __init__(
        self, binaries: Path, folder: Path, port: int, settings: Mapping[str, str] | None = None
    ) -> None:
        """``settings``: postgresql.conf values over :data:`SETTINGS` (as the file spells
        them: ``"on"``, ``"'256MB'"``)."""
        self.binaries = binaries
        self.folder = folder
        self.port = port
        self.data = folder / "data"
        self.log_path = folder / "server.log"
        self.running = False
        self.settings = {**SETTINGS, **(settings or {})}
        self._os_user: pwd.struct_passwd | None = None
        if os.geteuid() == 0:
            try:
                self._os_user = pwd.getpwnam(OS_USER_AS_ROOT)
            except KeyError:
                raise PostgresUnavailableError(
                    f"running as root and there is no {OS_USER_AS_ROOT!r} user to run "
                    "PostgreSQL as (initdb refuses root)"
                ) from None
            os.chown(folder, self._os_user.pw_uid, self._os_user.pw_gid)

    @property
    def url(self) -> str:
        """The conninfo of database :data:`DATABASE`, as psycopg accepts it."""
        return self.url_of(DATABASE)

    def url_of(self, database: str) -> str:
        """The conninfo of ``database`` on this server."""
        return f"postgresql://{SUPERUSER}@127.0.0.1:{self.port}/{database}"

    def _run(self, program: str, *args: str) -> subprocess.CompletedProcess[str]:
        """``program args``, as the ``postgres`` user when root; PG* variables of the
        environment left out, so that they cannot point it at another server."""
        user = self._os_user
        return subprocess.run(
            [str(self.binaries / program), *args],
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT_S,
            cwd=self.folder,
            env={key: value for key, value in os.environ.items() if not key.startswith("PG")},
            check=False,
            user=user.pw_uid if user else None,
            group=user.pw_gid if user else None,
            extra_groups=[] if user else None,
        )

    def init(self) -> None:
        """``initdb`` into ``folder/data``, then its settings appended to its postgresql.conf."""
        done = self._run(
            "initdb",
            f"--pgdata={self.data}",
            f"--username={SUPERUSER}",
            "--auth=trust",
            "--encoding=UTF8",
            "--locale=C",
            "--no-sync",
        )
        if done.returncode != 0:
            raise PostgresUnavailableError(
                f"initdb failed (exit {done.returncode}):\n{tail(done.stdout + done.stderr)}"
            )
        settings = {
            **self.settings,
            "port": str(self.port),
            "unix_socket_directories": f"'{self.folder}'",
        }
        with (self.data / "postgresql.conf").open("a", encoding="utf-8") as conf:
            conf.write("\n# a throwaway server for tests\n")
            conf.writelines(f"{name} = {value}\n" for name, value in settings.items())

    def start(self) -> None:
        """``pg_ctl start -w``: returns once the server accepts connections (again after
        ``stop()``: same data, same port)."""
        done = self._run(
            "pg_ctl",
            "start",
            f"--pgdata={self.data}",
            f"--log={self.log_path}",
            "--wait",
            f"--timeout={int(COMMAND_TIMEOUT_S)}",
        )
        if done.returncode != 0:
            # a server still starting when pg_ctl gave up is ended, not left behind
            self._run("pg_ctl", "stop", f"--pgdata={self.data}", "--mode=immediate")
            raise PostgresUnavailableError(
                f"the server did not start (pg_ctl exit {done.returncode}); "
                f"the end of its log:\n{tail(self.log_text())}"
            )
        self.running = True

    def log_text(self) -> str:
        """The server's log (``folder/server.log``) as text."""
        try:
            return self.log_path.read_text(errors="replace")
        except OSError:
            return "(no log)"

    def stop(self, mode: Literal["fast", "immediate"] = "fast") -> None:
        """``pg_ctl stop -m fast``: clients are cut off, and it returns once the server
        has exited. ``mode="immediate"`` ends it as a crash would (no shutdown
        checkpoint; the next start recovers)."""
        if not self.running:
            return
        done = self._run(
            "pg_ctl",
            "stop",
            f"--pgdata={self.data}",
            f"--mode={mode}",
            "--wait",
            f"--timeout={int(COMMAND_TIMEOUT_S)}",
        )
        if done.returncode != 0:
            raise RuntimeError(f"pg_ctl stop failed: {tail(done.stdout + done.stderr)}")
        self.running = False

    def kill(self) -> None:
        """The server ended as a crash would: ``stop(mode="immediate")``."""
        self.stop(mode="immediate")

    def close(self) -> None:
        """Stopped, and its folder removed."""
        try:
            self.stop()
        finally:
            shutil.rmtree(self.folder, ignore_errors=True)

    def create_database(self, name: str) -> str:
        """A new empty database ``name``; returns its url."""
        with psycopg.connect(self.url_of("postgres"), autocommit=True) as connection:
            connection.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
        return self.url_of(name)

    def drop_database(self, name: str) -> None:
        """Database ``name`` dropped; AssertionError when a connection to it is still open
        (a test that leaves one open leaks it)."""
        with psycopg.connect(self.url_of("postgres"), autocommit=True) as connection:
            try:
                connection.execute(sql.SQL("DROP DATABASE {}").format(sql.Identifier(name)))
            except psycopg.errors.ObjectInUse as err:
                raise AssertionError(f"database {name!r} still has a connection open") from err

    def __enter__(self) -> PostgresServer:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def start_postgres_server(
    folders: Iterable[Path] | None = None, settings: Mapping[str, str] | None = None
) -> PostgresServer:
    """A running server in a new temporary folder, with an empty database
    :data:`DATABASE` (its url: ``server.url``); PostgresUnavailableError says why not.
    ``folders``: where to look for the programs (default :func:`binary_folders`);
    ``settings``: postgresql.conf values over :data:`SETTINGS`."""
    binaries = find_binaries(binary_folders() if folders is None else folders)
    folder = Path(tempfile.mkdtemp(prefix="boltwatch-postgres-"))
    try:
        server = PostgresServer(binaries, folder, free_port(), settings)
    except BaseException:
        shutil.rmtree(folder, ignore_errors=True)
        raise
    try:
        server.init()
        server.start()
        server.create_database(DATABASE)
    except BaseException:
        server.close()
        raise
    return server
