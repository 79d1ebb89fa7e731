"""The intensity since service kept from the rows added (:mod:`.wear_since_service`).

Checked against the ledger's own whole-history figures (``WearLedger.tool``)
after every step of a random sequence: runs of several tools (late ones too,
ended before a service; loosenings among them), services, a second writer on
the same file, a redelivered run, the ledger reopened.
"""

from __future__ import annotations

import random
import sqlite3
from pathlib import Path

import pytest

from shared.contract import RunSummary
from shared.wear import ADDED_SINCE, WearLedger
from shared.wear import CONTRACT_LIMITS as LIMITS
from tests.support import factories

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000
TOOLS = (7, 8, 9)


def summary(
    run_id: int, tool_id: int, ended_ns: int, intensity: float, loosening: bool = False
) -> RunSummary:
    """A half-second run of ``tool_id`` at its own station (a tightening, or a loosening)."""
    return factories.summary(
        run_id,
        station=f"st{tool_id}",
        tool_id=tool_id,
        events=4,
        process_intensity=intensity,
        samples=500,
        started_ns=ended_ns - S_NS // 2,
        ended_ns=ended_ns,
        operation="loosening" if loosening else "tightening",
    )


def agrees(ledger: WearLedger, tool_id: int) -> None:
    interval = ledger.since_service(tool_id)
    whole = ledger.tool(tool_id)
    assert (interval.runs, interval.last_service_ns) == (
        whole.runs_since_service,
        whole.last_service_ns,
    )
    assert interval.intensity == pytest.approx(whole.intensity_since_service, rel=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_the_kept_interval_always_agrees_with_the_whole_history(seed: int, tmp_path: Path) -> None:
    rng = random.Random(seed)
    path = tmp_path / "wear.sqlite"
    ledger = WearLedger(path)
    other = WearLedger(path)  # a second writer: an import, another recorder
    run_ids = dict.fromkeys(TOOLS, 0)
    now_ns = T0_NS
    try:
        for _step in range(300):
            now_ns += S_NS
            tool_id = rng.choice(TOOLS)
            action = rng.random()
            if action < 0.08:
                rng.choice((ledger, other)).record_service(tool_id, "socket", now_ns)
            elif action < 0.12 and run_ids[tool_id]:  # redelivered: counted once
                again = summary(run_ids[tool_id], tool_id, now_ns, 1.0)
                assert not ledger.add_run(again, now_ns, LIMITS)
            else:
                run_ids[tool_id] += 1
                late_ns = rng.choice((0, 0, 0, 5 * S_NS))  # ended before a recent service
                loosening = rng.random() < 0.2  # its intensity counts, not as a tightening
                run = summary(
                    run_ids[tool_id], tool_id, now_ns - late_ns, rng.uniform(0, 9), loosening
                )
                assert rng.choice((ledger, other)).add_run(run, now_ns, LIMITS)
            if action > 0.97:
                ledger.close()
                ledger = WearLedger(path)
            agrees(ledger, rng.choice(TOOLS))
        for tool_id in TOOLS:
            agrees(ledger, tool_id)
            agrees(other, tool_id)
    finally:
        ledger.close()
        other.close()


def test_after_the_first_read_only_the_added_rows_are_read(tmp_path: Path) -> None:
    """SQLite's plan for the next read walks the rowids added, not the tool's index."""
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        ledger.add_run(summary(1, 7, T0_NS, 1.0), T0_NS, LIMITS)
    db = sqlite3.connect(tmp_path / "wear.sqlite")
    try:
        plan = db.execute(f"EXPLAIN QUERY PLAN {ADDED_SINCE}", (0, 1, 7, 0)).fetchall()
    finally:
        db.close()
    details = " ".join(str(row[-1]) for row in plan)
    assert "rowid>? AND rowid<?" in details, details
