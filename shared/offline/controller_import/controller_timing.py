"""The checks a controller run's clock must pass before it can become a recording.

A recording holds times as integer nanoseconds since 1970-01-01 UTC
(``Sample.time_ns``, MCAP log times, Rerun timestamps: 64-bit), so a run's
``date`` must lie between 1970-01-01 and 2262-04-11 23:47:16 UTC, and so must
``date`` + every ``time values`` entry. Anything else cannot be recorded
without inventing a time, and is refused with the file, the key and the index.

Times count from the run's ``date`` (the controller's clock) and never
decrease. A CS351 step repeats the previous step's last sample as its first
(same time, torque and angle): a repeated time is normal and kept. A time
that goes backwards, within a step or when a step restarts its clock at 0, is
refused: every figure the predictor takes into the wear ledger (periods,
f_ss, K1-K3, the intensity) is computed over time, and a recording whose
clock runs backwards plays out of order in every viewer, so the run would be
recorded with wrong figures; the line says where the clock went back and how
often, so the export can be fixed. How long a run lasts is no reason to
refuse it: a controller run is one file, whatever its times say.
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

from shared.contract import RunClock
from shared.errors import InputError

#: The last nanosecond a signed 64-bit ``time_ns`` holds (2262-04-11 23:47:16.854775807 UTC).
LAST_TIME_NS = 2**63 - 1
LAST_TIME_TEXT = "2262-04-11 23:47:16 UTC"
FIRST_TIME_TEXT = "1970-01-01 00:00:00 UTC"


def check_date(path: Path, date: datetime) -> int:
    """``date`` (UTC) in nanoseconds since 1970; InputError if a recording cannot hold it."""
    seconds = int(date.timestamp())
    if seconds < 0:
        raise InputError(
            f"{path}: 'date': {date:%Y-%m-%d %H:%M:%S} is before {FIRST_TIME_TEXT}, the first "
            "time a recording can hold (nanoseconds since 1970)"
        )
    date_ns = seconds * 1_000_000_000
    if date_ns >= LAST_TIME_NS:
        raise InputError(
            f"{path}: 'date': {date:%Y-%m-%d %H:%M:%S} is after {LAST_TIME_TEXT}, the last "
            "time a recording can hold (64-bit nanoseconds since 1970)"
        )
    return date_ns


def check_times(path: Path, date_ns: int, step_times_s: list[list[float]], where: str) -> None:
    """Refuse a run whose clock starts before ``date``, ends past 2262 or goes back.

    ``step_times_s`` holds each step's ``time values``; ``where`` is the key of
    the steps list (``tightening steps``), for the messages. A time no
    recording can hold is named first; then where the clock goes back.
    """
    backwards: list[tuple[int, int, float, float]] = []  # (step, index, previous, time)
    previous: float | None = None
    last_s = (LAST_TIME_NS - date_ns) / 1e9  # a time beyond this cannot be held
    for step, times in enumerate(step_times_s):
        for index, time_s in enumerate(times):
            if time_s < 0.0 or time_s >= last_s:
                _out_of_range(path, date_ns, f"{where}[{step}].graph.time values[{index}]", time_s)
            if previous is not None and time_s < previous:
                backwards.append((step, index, previous, time_s))
            previous = time_s
    if backwards:
        raise InputError(_backwards_line(path, where, backwards))


def _out_of_range(path: Path, date_ns: int, key: str, time_s: float) -> None:
    """Raise for a time before ``date`` or past the last nanosecond (the check's edge is
    a float; the exact integer decides)."""
    if time_s < 0.0:
        raise InputError(
            f"{path}: {key}: {time_s!r} s is before the run's 'date' (times count from it)"
        )
    if RunClock(date_ns).ns(time_s) >= LAST_TIME_NS:
        date = datetime.fromtimestamp(date_ns / 1e9, UTC)
        raise InputError(
            f"{path}: {key}: {time_s!r} s after 'date' {date:%Y-%m-%d %H:%M:%S} is past "
            f"{LAST_TIME_TEXT}, the last time a recording can hold (64-bit nanoseconds since 1970)"
        )


def _backwards_line(path: Path, where: str, backwards: list[tuple[int, int, float, float]]) -> str:
    step, index, previous, time_s = backwards[0]
    restarts = sum(1 for _, i, _, _ in backwards if i == 0)
    how = (
        f"step {step} restarts the clock at {time_s!r} s after {previous!r} s"
        if index == 0
        else f"time goes back from {previous!r} s to {time_s!r} s"
    )
    count = f"back {_times(len(backwards))} in the run"
    if restarts:
        count += f", {_times(restarts)} where a step starts"
    return (
        f"{path}: {where}[{step}].graph.time values[{index}]: {how} ({count}); refused: the "
        "predictor's figures and the recording need times that never decrease "
        "(repeated times are fine)"
    )


def _times(count: int) -> str:
    return "once" if count == 1 else f"{count} times"
