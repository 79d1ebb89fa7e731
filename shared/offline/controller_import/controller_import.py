"""Controller runs into the recordings folder, as the live station would have recorded them.

Each :class:`ControllerRun` becomes the messages a live station publishes
(``ToolState`` running, one ``Sample`` per controller sample with ``force_n``
None, ``ToolState`` done), the controller's own result (``ControllerResult``
on ``boltwatch/<st>/controller``), the run's ``TighteningResult`` made from
it (:mod:`shared.quality.controller_result`, on ``boltwatch/<st>/results``;
a loosening has none: it is no tightening, so the results store, the report
and its Cpk never count it; its ``ControllerResult``, ``RunSummary`` and the
``controller`` metadata record say ``operation`` loosening) and, when
given, what the predictor made of it
(:class:`~shared.stickslip.stopped_run.PredictorReplay`: events,
intensities, the advisory decision after the sample that caused each, and
the ``RunSummary`` at the end). They
are written with the recorder's own :class:`~shared.recordings.mcap.mcap_sink.McapSink`
(and :class:`~shared.recordings.rerun.rerun_sink.RerunSink`): same channels,
schemas, metadata records, folders and file names as a live recording, plus
a ``controller`` metadata record with the controller's header.

Times are the controller's own: a sample's ``time_ns`` = ``date`` + its
``time values`` entry, used as both log and publish time, repeated
timestamps and gaps unchanged; ``sequence`` is the sample's index in the
run. A run is one file, whatever its times say (the live recorder's
rotation bounds runs that never end; an imported run has its end).

A run is written whole or not at all (:mod:`shared.offline.controller_import.import_files`),
and counted in the wear ledger (by (station, run): never twice) before its
files get their real names, so a run in the folder is a run in the ledger.
The recording is not written here: this package may not import the
predictor; the import replays it (:mod:`.controller_replay`) and records the
messages beside its samples.

The ledger counts an imported run within the same bound as a live one
(:mod:`.wear_bound`), with the controller's own torque shutoff as the
tool's limit (:func:`controller_limits`) and no time limit but the run's
own duration (a controller run may last any time); a run beyond it is
refused and not written.
"""

from __future__ import annotations

import contextlib
import re
import sqlite3
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from shared.contract import RunSummary, Sample, ToolState, channels, encode, keys
from shared.errors import BoltwatchError, InputError
from shared.files import describe_os_error
from shared.offline.controller_import.controller_replay import replay_run
from shared.offline.controller_import.controller_run import ControllerRun
from shared.offline.controller_import.import_files import (
    put_in_place,
    read_copy,
    remove_leftovers,
    remove_temporary,
    temporary_path,
)
from shared.quality import controller_result
from shared.recordings import (
    FileMetadata,
    Received,
    classify,
    file_path,
    recording_files,
    rerun_path,
    run_file_prefix,
)
from shared.recordings.mcap import McapSink
from shared.stickslip import PredictorReplay
from shared.wear import CONTRACT_LIMITS, RunLimits

if TYPE_CHECKING:
    from shared.recordings.rerun import RerunOptions, RerunSink
    from shared.wear import WearLedger

STATION_PATTERN = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
DEFAULT_STATION = "cs351"
#: The controller's torque shutoff: a monitoring function whose limit stops the step
#: (``MFs``; ``MF`` functions only judge).
TORQUE_SHUTOFF = "MFs TorqueMax"


class RunNotWrittenError(BoltwatchError):
    """The run's files could not be written (disk, folder, Rerun); nothing of it was kept."""


@dataclass(frozen=True, slots=True)
class ImportedRun:
    source: Path
    mcap: Path | None  # None: skipped, already in the recordings folder
    rrd: Path | None
    samples: int
    existing: Path | None = None  # the finished import that was there already
    replaced: list[Path] = field(default_factory=list)  # unfinished imports replaced
    newly_counted: bool = False  # the run entered the wear ledger now
    summary: RunSummary | None = None  # the predictor's replay of it (None: skipped)


def check_station_id(station: str) -> str:
    if not STATION_PATTERN.match(station):
        raise InputError(
            f"--station {station!r}: expected 1-64 letters, digits, '_' or '-' (a zenoh key chunk)"
        )
    return station


def controller_messages(
    station: str, run: ControllerRun, replay: PredictorReplay | None = None
) -> Iterator[tuple[str, Any, int]]:
    """(topic, message, log time ns) of the run, in order, as a live station publishes them."""
    started_ns = run.started_ns
    outputs = replay.outputs if replay is not None else []
    next_output = 0
    yield channels.TOOL.topic, _state(station, run, "running", started_ns), started_ns
    for sequence, (time_ns, time_s, torque, angle) in enumerate(
        zip(run.times_ns, run.run_time_s, run.torque_nm, run.angle_deg, strict=True)
    ):
        sample = Sample(station, run.run_id, sequence, time_ns, torque, angle, None, time_s)
        yield channels.SAMPLES.topic, sample, time_ns
        while next_output < len(outputs) and outputs[next_output][0] <= sequence:
            _, topic, message = outputs[next_output]
            yield topic, message, time_ns
            next_output += 1
    end_ns = run.ended_ns
    for _, topic, message in outputs[next_output:]:
        yield topic, message, end_ns
    yield channels.TOOL.topic, _state(station, run, "done", end_ns), end_ns
    controller = run.result(station, end_ns)
    yield channels.CONTROLLER.topic, controller, end_ns
    summary = replay.summary if replay is not None else None
    if run.operation == "tightening":  # a loosening is no tightening: no tightening result
        result = controller_result(controller, summary, run.header.get("prg name", ""), "import")
        yield channels.RESULTS.topic, result, end_ns
    if replay is not None:
        yield channels.RUNS.topic, replay.summary, end_ns


def controller_limits(run: ControllerRun) -> RunLimits:
    """The run's torque limit for the wear ledger: the largest ``MFs TorqueMax`` nominal of
    its steps (the contract DBC's torque range when it has none); no time limit."""
    shutoffs = [
        function.nominal
        for step in run.steps
        for function in step.functions
        if function.name == TORQUE_SHUTOFF and function.nominal is not None and function.nominal > 0
    ]
    if not shutoffs:
        return RunLimits(
            CONTRACT_LIMITS.torque_limit_nm,
            None,
            f"the contract DBC's torque range (the run has no {TORQUE_SHUTOFF})",
        )
    top = max(shutoffs)
    return RunLimits(
        min(top, CONTRACT_LIMITS.torque_limit_nm), None, f"the controller's {TORQUE_SHUTOFF}"
    )


def import_run(
    run: ControllerRun,
    recordings: Path,
    station: str = DEFAULT_STATION,
    rerun: RerunOptions | None = None,
    ledger: WearLedger | None = None,
) -> ImportedRun:
    """Write ``run`` under ``recordings`` with the predictor's advisory replay of it
    (skipped if a finished import is there).

    RunNotWrittenError when its files cannot be written; nothing of it is left then.
    """
    canonical = file_path(recordings, station, run.run_id, run.started_ns, unique=False)
    day = canonical.parent
    prefix = run_file_prefix(station, run.run_id)
    copies = [read_copy(path) for path in recording_files(day, prefix)] if day.is_dir() else []
    finished = next((copy for copy in copies if copy.holds(len(run))), None)
    if finished is not None:
        counted = _count(ledger, finished.summary, controller_limits(run))
        return ImportedRun(run.source, None, None, len(run), finished.path, newly_counted=counted)
    unfinished = [copy.path for copy in copies if copy.imported]
    if day.is_dir():
        remove_leftovers(day, prefix)
    target = _target(canonical, unfinished)
    replay = replay_run(station, run)
    rrd = _write(run, station, target, rerun, replay)
    moves = [(temporary_path(target), target)]
    if rrd:  # the .rrd first: a .mcap under its real name means the run is complete
        moves.insert(0, (rerun_path(temporary_path(target)), rerun_path(target)))
    try:
        counted = _count(ledger, replay.summary, controller_limits(run))
    except BoltwatchError:
        remove_temporary([temporary for temporary, _ in moves])
        raise
    try:
        put_in_place(moves)
    except OSError as err:
        remove_temporary([temporary for temporary, _ in moves])
        raise RunNotWrittenError(
            f"cannot rename into {target}: {describe_os_error(err, target)}"
        ) from err
    replaced = _remove_replaced(unfinished, target, has_rrd=rrd)
    return ImportedRun(
        run.source,
        target,
        rerun_path(target) if rrd else None,
        len(run),
        replaced=replaced,
        newly_counted=counted,
        summary=replay.summary,
    )


def controller_record(run: ControllerRun) -> dict[str, str]:
    """The ``controller`` metadata record: where the run came from and its header."""
    record = {
        "source_file": run.source.name,
        "date_timezone": "none in the file; taken as UTC",
        "steps": ",".join(run.step_names),
        "samples": str(len(run)),
        "operation": run.operation,
    }
    record.update(run.header)
    return record


def _target(canonical: Path, unfinished: list[Path]) -> Path:
    """The run's real name: its canonical one, unless a file that is not an import has it."""
    candidate, copy = canonical, 2
    while candidate.exists() and candidate not in unfinished:
        candidate = canonical.with_name(f"{canonical.stem}_{copy}.mcap")
        copy += 1
    return candidate


def _write(
    run: ControllerRun,
    station: str,
    target: Path,
    rerun: RerunOptions | None,
    replay: PredictorReplay | None,
) -> bool:
    """Write the run under temporary names beside ``target``; True when a ``.rrd`` was too."""
    temporary = temporary_path(target)
    metadata = FileMetadata([], extra={"controller": controller_record(run)}, warn_unknown=False)
    records = metadata.for_file(station, run.run_id, run.tool_id, run.program_id)
    companion: RerunSink | None = None
    try:
        sink = McapSink(
            temporary, records, run.run_id, run.started_ns, f"boltwatch {metadata.version}"
        )
        try:
            if rerun is not None:
                companion = _open_rerun(run, station, target, rerun)
            for topic, message, time_ns in controller_messages(station, run, replay):
                received = _received(station, topic, message, time_ns)
                sink.write(received)
                if companion is not None:
                    companion.write(received)
            sink.close()
        except BaseException:
            sink.abandon()
            raise
        finally:
            if companion is not None:
                companion.close()
        if companion is not None and companion.failed:
            rrd = rerun_path(target)
            raise RunNotWrittenError(f"{rrd}: the Rerun recording failed (see the log above)")
    except OSError as err:
        remove_temporary([temporary, rerun_path(temporary)])
        _remove_if_empty(target.parent)
        raise RunNotWrittenError(_real_names(describe_os_error(err, target), target)) from err
    except BaseException:
        remove_temporary([temporary, rerun_path(temporary)])
        _remove_if_empty(target.parent)
        raise
    return companion is not None


def _remove_if_empty(folder: Path) -> None:
    """A day folder made for a run that failed goes with it (if nothing else is in it)."""
    with contextlib.suppress(OSError):
        folder.rmdir()


def _real_names(text: str, target: Path) -> str:
    """``text`` (an error) with the temporary names put back to the real ones: a person
    looks for the file the run was going to, not for a hidden one that is gone."""
    return text.replace(str(temporary_path(target).with_suffix("")), str(target.with_suffix("")))


def _open_rerun(run: ControllerRun, station: str, target: Path, options: RerunOptions) -> RerunSink:
    """The run's Rerun sink, writing the temporary ``.rrd`` beside ``target``."""
    from shared.recordings.rerun import RerunSink

    temporary = rerun_path(temporary_path(target))
    try:
        return RerunSink(temporary, station, run.run_id, run.started_ns, options, target.stem)
    except OSError:
        raise
    except Exception as err:  # the rerun SDK raises its own errors
        why = _real_names(str(err), target)
        raise RunNotWrittenError(
            f"{rerun_path(target)}: the Rerun recording cannot be opened: {why}"
        ) from err


def _count(ledger: WearLedger | None, summary: RunSummary | None, limits: RunLimits) -> bool:
    """Add the run to the wear ledger; True when it was not in it yet.

    RefusedSummaryError (bad input) when the run is beyond ``limits``.
    """
    if ledger is None or summary is None:
        return False
    try:
        return ledger.add_run(summary, time.time_ns(), limits)
    except sqlite3.Error as err:
        raise RunNotWrittenError(
            f"{ledger.path}: the wear ledger cannot be written: {err}"
        ) from err


def _remove_replaced(unfinished: list[Path], target: Path, has_rrd: bool) -> list[Path]:
    """Remove the unfinished imports the new file replaces (and their ``.rrd``)."""
    replaced: list[Path] = []
    for path in unfinished:
        if path != target:
            path.unlink(missing_ok=True)
        if path != target or not has_rrd:
            rerun_path(path).unlink(missing_ok=True)
        replaced.append(path)
    return replaced


def _state(station: str, run: ControllerRun, state: Any, time_ns: int) -> ToolState:
    return ToolState(station, run.run_id, run.tool_id, run.program_id, state, time_ns)


def _received(station: str, topic: str, message: Any, time_ns: int) -> Received:
    return classify(keys.station_key(station, topic), encode(message), time_ns)
