"""A results store as an older boltwatch left it, to open with this one (its migration).

:func:`old_store` makes the tables of an older version (``MIGRATIONS[:version]``,
the statements that version ran) and fills them as it did: each result's row
with the columns that version had, and its steps. :func:`version_1_store` is
the store before the plant model (no ``plant``, no ``station_name``),
:func:`version_2_store` the one before the part's source (no ``part_source``),
:func:`version_4_store` the one before a final stage's pulses (no ``pulses``),
:func:`version_5_store` the one before multi-spindle stations (no ``spindle``, no
``sync_id``, no ``cycle_results``).
"""

from __future__ import annotations

from collections.abc import Sequence

from shared.results import MIGRATIONS, ResultsDatabase, StoredResult, StoreTarget, migrate
from shared.results.results_schema import STEP_COLUMNS, TIGHTENING_COLUMNS
from shared.results.stored_result import step_rows, to_row

#: the columns each version added to ``tightenings``
ADDED_IN = {
    2: ("plant", "station_name"),
    3: ("part_source",),
    5: ("pulses",),
    6: ("spindle", "sync_id"),
}
#: the columns version 2 added to ``tightenings`` (the plant model)
ADDED_IN_2 = ADDED_IN[2]


def columns_of(version: int) -> tuple[str, ...]:
    """The columns of ``tightenings`` in a store of ``version``."""
    later = {column for added, names in ADDED_IN.items() if added > version for column in names}
    return tuple(column for column in TIGHTENING_COLUMNS if column not in later)


VERSION_1_COLUMNS = columns_of(1)


def old_store(target: StoreTarget, results: Sequence[StoredResult], version: int) -> None:
    """A store of ``version`` at ``target`` holding ``results`` (what that version did not
    keep left out)."""
    columns = columns_of(version)
    insert = (
        f"INSERT INTO tightenings ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})"
    )
    insert_step = (
        f"INSERT INTO tightening_steps ({', '.join(STEP_COLUMNS)}) "
        f"VALUES ({', '.join('?' * len(STEP_COLUMNS))})"
    )
    with ResultsDatabase(target) as database:
        assert migrate(database, MIGRATIONS[:version]) == 0, f"{target}: not a new store"
        with database.transaction():
            for stored in results:
                row = dict(zip(TIGHTENING_COLUMNS, to_row(stored), strict=True))
                database.execute(insert, [row[column] for column in columns])
                database.execute_many(insert_step, step_rows(stored))


def version_1_store(target: StoreTarget, results: Sequence[StoredResult]) -> None:
    """A store of version 1 at ``target`` holding ``results`` (their plant and station name,
    which version 1 did not keep, left out)."""
    old_store(target, results, 1)


def version_2_store(target: StoreTarget, results: Sequence[StoredResult]) -> None:
    """A store of version 2 at ``target`` holding ``results`` (their part's source, which
    version 2 did not keep, left out)."""
    old_store(target, results, 2)


def version_4_store(target: StoreTarget, results: Sequence[StoredResult]) -> None:
    """A store of version 4 at ``target`` holding ``results`` (their pulses, which version 4
    did not keep, left out)."""
    old_store(target, results, 4)


def version_5_store(target: StoreTarget, results: Sequence[StoredResult]) -> None:
    """A store of version 5 at ``target`` holding ``results`` (their spindle and sync id,
    which version 5 did not keep, left out)."""
    old_store(target, results, 5)
