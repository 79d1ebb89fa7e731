"""Runs still waiting for the wear ledger when the recorder stops: kept on disk till they count.

While the ledger fails (a full disk) or is broken, RunSummaries wait in the
recorder's memory (:class:`~.wear_watch.WearWatch`). When the recorder stops
with runs still waiting, they are written to ``<ledger>.waiting`` (e.g.
``recordings/wear.sqlite.waiting``) beside the ledger, one JSON object per
line (``received_ns``, ``summary``), whole or not at all (a temporary file
renamed over it). The next recorder reads them back at its start and counts
them first; the file is removed once every run in it is in the ledger. A
run counts once per (station, run_id), so a run counted twice over a crash
is still one run.

A file that cannot be read back is not lost either: it is renamed
``<ledger>.waiting.unreadable-<UTC stamp>`` and logged.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Iterable
from datetime import UTC, datetime
from pathlib import Path

from shared.contract import RunSummary, decode, encode
from shared.errors import InputError

LOG = logging.getLogger(__name__)

Waiting = tuple[RunSummary, int]  # the summary and when the recorder received it (ns)


def waiting_path(ledger_file: Path) -> Path:
    return ledger_file.with_name(f"{ledger_file.name}.waiting")


def save_waiting(path: Path, waiting: Iterable[Waiting]) -> int:
    """Write every waiting run to ``path`` (replacing it); how many. OSError when it cannot."""
    lines = [
        f'{{"received_ns": {received_ns}, "summary": {encode(summary).decode()}}}\n'
        for summary, received_ns in waiting
    ]
    temporary = path.with_name(f".{path.name}.{os.getpid()}")
    try:
        with temporary.open("w", encoding="utf-8") as handle:
            handle.writelines(lines)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return len(lines)


def load_waiting(path: Path) -> list[Waiting]:
    """The runs a stopped recorder left waiting in ``path`` (none when there is no file)."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return []
    except (OSError, UnicodeDecodeError) as err:
        _set_aside(path, str(err))
        return []
    waiting: list[Waiting] = []
    for number, line in enumerate(text.splitlines(), start=1):
        try:
            entry = json.loads(line)
            summary = decode(RunSummary, json.dumps(entry["summary"]).encode())
            received_ns = entry["received_ns"]
            if not isinstance(received_ns, int):
                raise InputError(f"received_ns: expected an integer, got {received_ns!r}")
        except (ValueError, TypeError, KeyError, InputError) as err:
            _set_aside(path, f"line {number}: {err}")
            return []
        waiting.append((summary, received_ns))
    return waiting


def _set_aside(path: Path, why: str) -> None:
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    target = path.with_name(f"{path.name}.unreadable-{stamp}")
    try:
        os.rename(path, target)
    except OSError as err:
        LOG.error("runs waiting for the wear ledger in %s unreadable (%s), left there: %s",
                  path, why, err)  # fmt: skip
        return
    LOG.error(
        "runs waiting for the wear ledger in %s unreadable (%s); kept as %s, not counted",
        path,
        why,
        target,
    )
