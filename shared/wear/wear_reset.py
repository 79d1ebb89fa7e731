"""``boltwatch wear reset``: a broken ledger moved aside (kept) and a new one started.

Only a broken ledger is moved (:mod:`.wear_ledger_file`: empty, not SQLite,
another schema, or corrupt as ``PRAGMA quick_check`` reads it); a healthy
one is left alone, and so is a ledger a process has open (SQLite's WAL lock
shows it: a recorder or an import writing it). A recorder whose ledger broke
holds no connection to it: it waits with its summaries in memory, and puts
them into the new ledger at its next check (within two seconds).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from shared.errors import InputError
from shared.wear.wear_ledger import WearLedger
from shared.wear.wear_ledger_file import COMPANIONS, BrokenLedgerError, holder_pid, move_aside


@dataclass(frozen=True, slots=True)
class LedgerReset:
    """What ``reset_ledger`` did."""

    broken: str  # what was wrong with the file
    kept: list[Path]  # the broken file (and its -wal, -shm) under their new names
    ledger: Path  # the new ledger


def reset_ledger(path: Path) -> LedgerReset | None:
    """Move the broken ledger at ``path`` aside and start a new one; None: no ledger there.

    InputError when it is healthy or a process has it open.
    """
    if not path.exists():
        return None
    pid = holder_pid(path)
    if pid is not None:
        raise InputError(
            f"{path}: open in process {pid} ({_command_of(pid)}); a ledger in use is not "
            "moved: stop that process first"
        )
    broken = problem_of(path)
    if broken is None:
        raise InputError(f"{path}: a healthy wear ledger; nothing to reset")
    target = move_aside(path)
    WearLedger(path).close()  # a new ledger (or the one a recorder started meanwhile)
    kept = [Path(f"{target}{end}") for end in ("", *COMPANIONS)]
    return LedgerReset(broken, [name for name in kept if name.exists()], path)


def problem_of(path: Path) -> str | None:
    """What makes the ledger at ``path`` broken, read through; None when it is healthy."""
    try:
        ledger = WearLedger(path, read_only=True)
    except BrokenLedgerError as err:
        return err.what
    try:
        ledger.verify()
    except BrokenLedgerError as err:
        return err.what
    finally:
        ledger.close()
    return None


def _command_of(pid: int) -> str:
    try:
        words = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return "command unknown"
    text = " ".join(word.decode(errors="replace") for word in words if word)
    return text[:120] or "command unknown"
