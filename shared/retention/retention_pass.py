"""One pass of a retention policy over one recordings folder: its files listed, judged and
planned (:func:`plan_pass`); the recorder's thread and ``boltwatch recordings prune`` both
run it, then delete what it planned (:func:`~.pruning.delete_planned`) or, dry, say it.

:func:`retention_scopes` finds, in station files, each recordings folder, the
stations recorded into it, their ``[retention]`` section and their results
store: station files sharing a folder must agree on both (a folder has one
policy, and one store says which results are stored), else a ConfigError
naming both files and the key.
"""

from __future__ import annotations

import shutil
import threading
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path

from shared.config import AnyStation, RetentionSection
from shared.errors import ConfigError
from shared.files import real_path
from shared.recordings import loop_lines
from shared.results import ResultsStore, StoreTarget, store_target
from shared.retention.disk_usage import Measure, disk_usage_of
from shared.retention.file_holdings import FileHoldings, FileResultsCache
from shared.retention.recording_files import RecordingFile, list_recordings
from shared.retention.retention_plan import RetentionPlan, plan_retention

#: why a file was not judged: the pass was stopped
STOPPED = "not judged: the pass was stopped"


@dataclass(frozen=True)
class RetentionScope:
    """A recordings folder, the stations recorded into it, their policy and their store."""

    folder: Path
    stations: tuple[str, ...]
    policy: RetentionSection
    target: StoreTarget
    station_files: tuple[Path, ...]


def retention_scopes(stations: Sequence[AnyStation]) -> list[RetentionScope]:
    """One scope per recordings folder of ``stations`` (in the order first named)."""
    by_folder: dict[Path, list[AnyStation]] = {}
    for station in stations:
        by_folder.setdefault(real_path(station.recordings_folder), []).append(station)
    scopes = []
    for folder, sharing in by_folder.items():
        first = sharing[0]
        policy = first.config.retention
        database = first.config.recorder.results_database
        for other in sharing[1:]:
            for name, value in other.config.retention.model_dump().items():
                if getattr(policy, name) != value:
                    raise ConfigError(
                        f"{other.path}: retention.{name}: {_text(value)} differs from "
                        f"{_text(getattr(policy, name))} of {first.path}; the stations of "
                        f"one recordings folder ({folder}) have one [retention] section"
                    )
            if other.config.recorder.results_database != database:
                raise ConfigError(
                    f"{other.path}: recorder.results_database differs from that of "
                    f"{first.path}; the stations of one recordings folder ({folder}) have "
                    "one results store"
                )
        scopes.append(
            RetentionScope(
                folder=folder,
                stations=tuple(station.station_id for station in sharing),
                policy=policy,
                target=store_target(folder, database),
                station_files=tuple(station.path for station in sharing),
            )
        )
    return scopes


def plan_pass(
    scope: RetentionScope,
    store: ResultsStore,
    cache: FileResultsCache,
    now_ns: int,
    open_paths: Collection[Path] = (),
    measure: Measure = shutil.disk_usage,
    stop: threading.Event | None = None,
) -> RetentionPlan:
    """What the policy deletes in ``scope`` now (``open_paths``: files the recorder has
    open; ``measure``: the disk, as :func:`shutil.disk_usage`; ``stop`` set: no file more
    is read, the rest are kept: a recorder stopping in a long first pass stops now).
    StoreError when the store cannot be asked: then nothing is planned; InputError when the
    folder is a symlink loop. A symlink loop in it is never touched: a line in the plan's
    ``skipped``."""
    loops: list[Path] = []
    files = list_recordings(scope.folder, scope.stations, now_ns, open_paths, loops)
    cache.keep_only(files)
    usage = None
    if scope.policy.max_disk_used_pct is not None:
        usage = disk_usage_of(scope.folder, measure)

    def holdings(recording: RecordingFile) -> FileHoldings:
        if stop is not None and stop.is_set():
            return FileHoldings(unreadable=STOPPED)
        return cache.holdings(recording, store)

    plan = plan_retention(files, scope.policy, now_ns, holdings, usage)
    plan.skipped = loop_lines(loops)
    return plan


def _text(value: object) -> str:
    return "none" if value is None else str(value)
