"""The results store's tables and their versions: one list of migrations for both databases.

``tightenings``: one row per tightening, keyed by (station, run_id), so a
result heard twice (a spool's resend, a rebuild over files already read) is
one row. It holds what a quality engineer asks about: the part (and where a
live run's part came from, ``part_source``: scanned, restored from the line
when the predictor started, unknown; NULL: not said), the program, the tool,
where it was tightened (the plant, the line, the station's name for people:
the station file's ``[station]`` when it was stored), when it ended, OK/NOK
and why, the final torque, angle and preload each with its window and
status, what stopped the tool, the stick-slip events and intensity, who judged
it (``source``), and where its recording is (``recording``: the MCAP file's
path on ``recording_host``).
A multi-spindle station's tightening (one spindle's run of a synchronised
cycle) says its ``spindle`` (1..N) and its cycle's ``sync_id``; a
single-spindle station's leaves both NULL.
``cycle_results``: the common result of each multi-spindle cycle (OK only when
every spindle is), one row per spindle's run of it, keyed as its tightening
is: a reader finds a tightening's cycle by its key, whichever of the two came
first (a spool's resend, a rebuild).
``tightening_steps``: the steps of a controller's program, one row each.
``refused_tightenings``: the columns of ``tightenings``, for the tightenings
whose figures cannot be a measurement (:mod:`.refused_results`): kept aside,
never a result to a reader.
``recordings_read``: which recordings ``results rebuild`` (and the
recorder's catch-up at start) has read, so reading again skips them.
``store_version``: the schema version.

A store of an older version is brought up to :data:`SCHEMA_VERSION` by the
first writer that opens it (:func:`migrate`), each step in one transaction
under the store's lock, so two recorders starting at once migrate it once
and nothing already stored is lost; a store of a newer version than this
boltwatch knows is refused, never written into.
"""

from __future__ import annotations

from shared.results.refused_results import IMPLAUSIBLE_SQL
from shared.results.results_database import ResultsDatabase, StoreError

#: the version this boltwatch writes; MIGRATIONS[v - 1] makes version v
SCHEMA_VERSION = 6

TIGHTENING_COLUMNS = (
    "station", "run_id", "plant", "line", "station_name", "tightening_id", "tool_id",
    "program_id", "program_name", "part_id", "batch_counter", "ended_ns", "result", "nok_reasons",
    "torque_nm", "torque_min_nm", "torque_max_nm", "torque_status",
    "angle_deg", "angle_min_deg", "angle_max_deg", "angle_status",
    "force_n", "force_min_n", "force_max_n", "force_status",
    "stop_reason", "events", "process_intensity", "source",
    "recording", "recording_host", "stored_ns", "part_source", "pulses", "spindle", "sync_id",
)  # fmt: skip
CYCLE_COLUMNS = (
    "station", "run_id", "sync_id", "spindle", "spindles", "result", "nok_reasons", "ended_ns",
    "part_id", "program_id", "source", "stored_ns",
)  # fmt: skip
STEP_COLUMNS = (
    "station", "run_id", "step_index", "name", "function", "nominal", "actual", "status",
)  # fmt: skip

_VERSION_1 = (
    """CREATE TABLE tightenings (
        station TEXT NOT NULL,
        run_id BIGINT NOT NULL,
        line TEXT NOT NULL,
        tightening_id BIGINT NOT NULL,
        tool_id BIGINT NOT NULL,
        program_id BIGINT NOT NULL,
        program_name TEXT NOT NULL,
        part_id TEXT,
        batch_counter BIGINT,
        ended_ns BIGINT NOT NULL,
        result TEXT NOT NULL,
        nok_reasons TEXT NOT NULL,
        torque_nm DOUBLE PRECISION, torque_min_nm DOUBLE PRECISION,
        torque_max_nm DOUBLE PRECISION, torque_status TEXT NOT NULL,
        angle_deg DOUBLE PRECISION, angle_min_deg DOUBLE PRECISION,
        angle_max_deg DOUBLE PRECISION, angle_status TEXT NOT NULL,
        force_n DOUBLE PRECISION, force_min_n DOUBLE PRECISION,
        force_max_n DOUBLE PRECISION, force_status TEXT NOT NULL,
        stop_reason TEXT,
        events BIGINT,
        process_intensity DOUBLE PRECISION,
        source TEXT NOT NULL,
        recording TEXT,
        recording_host TEXT,
        stored_ns BIGINT NOT NULL,
        PRIMARY KEY (station, run_id)
    )""",
    "CREATE INDEX tightenings_by_part ON tightenings (part_id, ended_ns)",
    "CREATE INDEX tightenings_by_time ON tightenings (ended_ns)",
    "CREATE INDEX tightenings_by_station ON tightenings (station, ended_ns)",
    "CREATE INDEX tightenings_by_line ON tightenings (line, ended_ns)",
    "CREATE INDEX tightenings_by_program ON tightenings (program_id, ended_ns)",
    "CREATE INDEX tightenings_by_tool ON tightenings (tool_id, ended_ns)",
    "CREATE INDEX tightenings_by_stored ON tightenings (stored_ns)",
    """CREATE TABLE tightening_steps (
        station TEXT NOT NULL,
        run_id BIGINT NOT NULL,
        step_index BIGINT NOT NULL,
        name TEXT NOT NULL,
        function TEXT NOT NULL,
        nominal DOUBLE PRECISION,
        actual DOUBLE PRECISION,
        status TEXT NOT NULL,
        PRIMARY KEY (station, run_id, step_index)
    )""",
    """CREATE TABLE recordings_read (
        recording_host TEXT NOT NULL,
        recording TEXT NOT NULL,
        size_bytes BIGINT NOT NULL,
        modified_ns BIGINT NOT NULL,
        results BIGINT NOT NULL,
        read_ns BIGINT NOT NULL,
        PRIMARY KEY (recording_host, recording)
    )""",
)

# the plant model: the station's plant, and its name for people, on each row (a row made
# before has neither: ''). ADD COLUMN with a constant default rewrites no row in either
# database (SQLite changes the table's schema; PostgreSQL 11+ keeps the default in the
# catalogue); only the index reads the table.
_VERSION_2 = (
    "ALTER TABLE tightenings ADD COLUMN plant TEXT NOT NULL DEFAULT ''",
    "ALTER TABLE tightenings ADD COLUMN station_name TEXT NOT NULL DEFAULT ''",
    "CREATE INDEX tightenings_by_plant ON tightenings (plant, ended_ns)",
)

# where a live run's part came from (TighteningResult.part_source): a row made before says
# nothing (NULL), as a result recorded before does. ADD COLUMN of a nullable column with no
# default rewrites no row in either database.
_VERSION_3 = ("ALTER TABLE tightenings ADD COLUMN part_source TEXT",)

#: the columns of tightenings at version 4 (a later version's are not there yet)
_COLUMNS_4 = TIGHTENING_COLUMNS[: TIGHTENING_COLUMNS.index("part_source") + 1]

# one rule for what a result is (.refused_results): a tightening whose figures cannot be a
# measurement is kept aside, in a table of the same columns, and no reader counts it. The
# rows an older boltwatch stored in tightenings (results rebuild stored every result) are
# moved there, their steps where they are: two reads of the table, once.
_VERSION_4 = (
    """CREATE TABLE refused_tightenings (
        station TEXT NOT NULL,
        run_id BIGINT NOT NULL,
        plant TEXT NOT NULL,
        line TEXT NOT NULL,
        station_name TEXT NOT NULL,
        tightening_id BIGINT NOT NULL,
        tool_id BIGINT NOT NULL,
        program_id BIGINT NOT NULL,
        program_name TEXT NOT NULL,
        part_id TEXT,
        batch_counter BIGINT,
        ended_ns BIGINT NOT NULL,
        result TEXT NOT NULL,
        nok_reasons TEXT NOT NULL,
        torque_nm DOUBLE PRECISION, torque_min_nm DOUBLE PRECISION,
        torque_max_nm DOUBLE PRECISION, torque_status TEXT NOT NULL,
        angle_deg DOUBLE PRECISION, angle_min_deg DOUBLE PRECISION,
        angle_max_deg DOUBLE PRECISION, angle_status TEXT NOT NULL,
        force_n DOUBLE PRECISION, force_min_n DOUBLE PRECISION,
        force_max_n DOUBLE PRECISION, force_status TEXT NOT NULL,
        stop_reason TEXT,
        events BIGINT,
        process_intensity DOUBLE PRECISION,
        source TEXT NOT NULL,
        recording TEXT,
        recording_host TEXT,
        stored_ns BIGINT NOT NULL,
        part_source TEXT,
        PRIMARY KEY (station, run_id)
    )""",
    f"INSERT INTO refused_tightenings ({', '.join(_COLUMNS_4)}) "
    f"SELECT {', '.join(_COLUMNS_4)} FROM tightenings WHERE {IMPLAUSIBLE_SQL}",
    f"DELETE FROM tightenings WHERE {IMPLAUSIBLE_SQL}",
)

# a final stage's pulses back to the target (TighteningResult.pulses): NULL for a run without
# a final stage, and for a row made before (nothing rewritten, as in version 3), in both
# tables of tightenings
_VERSION_5 = (
    "ALTER TABLE tightenings ADD COLUMN pulses BIGINT",
    "ALTER TABLE refused_tightenings ADD COLUMN pulses BIGINT",
)

# multi-spindle stations: a tightening's spindle and its cycle's sync id (NULL for a
# single-spindle station's, and for a row made before: nothing rewritten, as in version 3), in
# both tables of tightenings; the cycles' common results, one row per spindle's run, keyed as
# the run's tightening
_VERSION_6 = (
    "ALTER TABLE tightenings ADD COLUMN spindle BIGINT",
    "ALTER TABLE tightenings ADD COLUMN sync_id BIGINT",
    "ALTER TABLE refused_tightenings ADD COLUMN spindle BIGINT",
    "ALTER TABLE refused_tightenings ADD COLUMN sync_id BIGINT",
    """CREATE TABLE cycle_results (
        station TEXT NOT NULL,
        run_id BIGINT NOT NULL,
        sync_id BIGINT NOT NULL,
        spindle BIGINT NOT NULL,
        spindles BIGINT NOT NULL,
        result TEXT NOT NULL,
        nok_reasons TEXT NOT NULL,
        ended_ns BIGINT NOT NULL,
        part_id TEXT,
        program_id BIGINT NOT NULL,
        source TEXT NOT NULL,
        stored_ns BIGINT NOT NULL,
        PRIMARY KEY (station, run_id)
    )""",
    "CREATE INDEX cycle_results_by_sync ON cycle_results (station, sync_id, ended_ns)",
)

#: the statements that bring a store from version v - 1 to v, for v = 1, 2, ...
MIGRATIONS: tuple[tuple[str, ...], ...] = (
    _VERSION_1,
    _VERSION_2,
    _VERSION_3,
    _VERSION_4,
    _VERSION_5,
    _VERSION_6,
)


def migrate(database: ResultsDatabase, migrations: tuple[tuple[str, ...], ...] = MIGRATIONS) -> int:
    """Bring the store to the last version of ``migrations``; the version it had (0: new).
    StoreError when it is newer than this boltwatch."""
    known = len(migrations)
    with database.transaction(lock=True):
        database.execute("CREATE TABLE IF NOT EXISTS store_version (version BIGINT NOT NULL)")
        found = database.rows("SELECT version FROM store_version")
        if not found:
            database.execute("INSERT INTO store_version (version) VALUES (0)")
        had = int(found[0][0]) if found else 0
        if had > known:
            raise StoreError(
                f"results store {database.target}: version {had} is newer than this "
                f"boltwatch's {known}; upgrade boltwatch to write into it"
            )
        for version in range(had + 1, known + 1):
            for statement in migrations[version - 1]:
                database.execute(statement)
            database.execute("UPDATE store_version SET version = ?", (version,))
    return had


def version_of(database: ResultsDatabase) -> int:
    """The store's version without changing it (0: no store there yet)."""
    with database.transaction():
        tables = database.rows(
            "SELECT name FROM sqlite_master WHERE name = 'store_version'"
            if database.dialect == "sqlite"
            else "SELECT tablename FROM pg_tables WHERE tablename = 'store_version'"
        )
        if not tables:
            return 0
        found = database.rows("SELECT version FROM store_version")
    return int(found[0][0]) if found else 0
