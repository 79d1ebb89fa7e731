"""One whole run as a station publishes it, and the files a recorder made of it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from shared.config import LoadedStation
from shared.contract import (
    Intensity,
    Sample,
    StopDecision,
    ToolState,
)
from tests.support import factories

T0_NS = 1_700_000_000_000_000_000


SAMPLES = 300


EVENTS = 3


def run_messages(run_id: int, samples: int) -> list[tuple[str, Any]]:
    """(topic, message) of one whole run, in publishing order."""
    t = T0_NS + run_id * 10_000_000_000
    out: list[tuple[str, Any]] = [("tool", ToolState("st1", run_id, 7, 1, "running", t))]
    for n in range(samples):
        force = None if n % 50 == 0 else 10_000.0 + n
        out.append(
            ("samples", Sample("st1", run_id, n, t + n * 1_000_000, 1.0 + n, 0.1 * n, force))
        )
        if n % 100 == 99:
            j = n // 100 + 1
            event = factories.event(
                run_id,
                j,
                time_ns=t + n * 1_000_000,
                time_s=n / 1000,
                peak_torque_nm=100.0,
                min_torque_nm=90.0,
                torque_drop_nm=10.0,
                force_step_n=500.0,
                period_s=0.1,
                f_ss_hz=10.0,
            )
            out.append(("events", event))
            out.append(("intensity", Intensity("st1", run_id, t + n * 1_000_000, 0.5, 0.5 * j)))
    end = t + samples * 1_000_000
    out.append(
        (
            "decision",
            StopDecision(
                "st1",
                run_id,
                end,
                samples / 1000,
                "plateau_closest",
                "",
                120.0,
                55_000.0,
                56_000.0,
                end + 5,
            ),
        )
    )
    out.append(("tool", ToolState("st1", run_id, 7, 1, "done", end + 1)))
    out.append(
        (
            "runs",
            factories.summary(
                run_id,
                events=EVENTS,
                stop_reason="plateau_closest",
                process_intensity=1.5,
                samples=samples,
                started_ns=t,
                ended_ns=end + 1,
            ),
        )
    )
    return out


def recorded_files(loaded: LoadedStation) -> list[Path]:
    return sorted(loaded.recordings_folder.glob("st1/*/*.mcap"))
