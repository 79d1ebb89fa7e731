"""One whole run as a station publishes it, and the files a recorder made of it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from shared.config import LoadedStation
from shared.contract import (
    Intensity,
    RunSummary,
    Sample,
    StickSlipEvent,
    StopDecision,
    ToolState,
)

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
            event = StickSlipEvent(
                "st1",
                run_id,
                j,
                t + n * 1_000_000,
                n / 1000,
                100.0,
                90.0,
                10.0,
                20_000.0,
                500.0,
                0.1,
                10.0,
                1.0,
                2.0,
                3.0,
                0.5,
                0.5 * j,
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
            RunSummary(
                "st1",
                run_id,
                7,
                1,
                "done",
                56_000.0,
                None,
                55_000.0,
                120.0,
                -1.8,
                EVENTS,
                "plateau_closest",
                1.5,
                samples,
                t,
                end + 1,
            ),
        )
    )
    return out


def recorded_files(loaded: LoadedStation) -> list[Path]:
    return sorted(loaded.recordings_folder.glob("st1/*/*.mcap"))
