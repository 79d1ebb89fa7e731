"""A results store as an older boltwatch left it, to open with this one (its migration).

:func:`version_1_store` makes the tables of version 1 (``MIGRATIONS[:1]``, the
statements that version ran) and fills them as it did: each result's row
with the columns version 1 had (no ``plant``, no ``station_name``), and its steps.
"""

from __future__ import annotations

from collections.abc import Sequence

from shared.results import MIGRATIONS, ResultsDatabase, StoredResult, StoreTarget, migrate
from shared.results.results_schema import STEP_COLUMNS, TIGHTENING_COLUMNS
from shared.results.stored_result import step_rows, to_row

#: the columns version 2 added to ``tightenings`` (the plant model)
ADDED_IN_2 = ("plant", "station_name")
VERSION_1_COLUMNS = tuple(c for c in TIGHTENING_COLUMNS if c not in ADDED_IN_2)


def version_1_store(target: StoreTarget, results: Sequence[StoredResult]) -> None:
    """A store of version 1 at ``target`` holding ``results`` (their plant and station name,
    which version 1 did not keep, left out)."""
    insert = (
        f"INSERT INTO tightenings ({', '.join(VERSION_1_COLUMNS)}) "
        f"VALUES ({', '.join('?' * len(VERSION_1_COLUMNS))})"
    )
    insert_step = (
        f"INSERT INTO tightening_steps ({', '.join(STEP_COLUMNS)}) "
        f"VALUES ({', '.join('?' * len(STEP_COLUMNS))})"
    )
    with ResultsDatabase(target) as database:
        assert migrate(database, MIGRATIONS[:1]) == 0, f"{target}: not a new store"
        with database.transaction():
            for stored in results:
                row = dict(zip(TIGHTENING_COLUMNS, to_row(stored), strict=True))
                database.execute(insert, [row[column] for column in VERSION_1_COLUMNS])
                database.execute_many(insert_step, step_rows(stored))
