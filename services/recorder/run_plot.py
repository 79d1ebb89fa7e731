"""A PNG of one recorded run: torque and force over time, detected peaks and plateaus.

Like the paper's Figures 10-23: torque (Nm) on the left axis, preload force
(N) on the right, each stick-slip event's peak torque T_max,j and plateau
force F_j marked, the stop decision as a vertical line. Time counts from the
run's first sample (``Sample.time_ns``, the same clock as the events').
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from services.recorder.recording_reader import RecordingScan
from services.recorder.trace_export import SAMPLE_SCHEMA
from shared.errors import InputError


def _decoded(scan: RecordingScan) -> dict[str, list[dict[str, Any]]]:
    by_schema: dict[str, list[dict[str, Any]]] = {}
    for schema, _, message in scan.messages():
        if schema is not None:
            by_schema.setdefault(schema.name, []).append(json.loads(message.data))
    return by_schema


def plot_run(source: Path, target: Path, run_id: int | None = None) -> tuple[int, int]:
    """Draw the run into ``target`` (PNG); (samples, events) drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scan = RecordingScan(source)
    decoded = _decoded(scan)
    samples = decoded.get(SAMPLE_SCHEMA, [])
    if run_id is None and samples:
        run_id = max({s["run_id"] for s in samples}, key=[s["run_id"] for s in samples].count)
    samples = [s for s in samples if s["run_id"] == run_id]
    if not samples:
        raise InputError(f"{source}: no samples to plot")
    events = [e for e in decoded.get("boltwatch.StickSlipEvent", []) if e["run_id"] == run_id]
    decisions = [d for d in decoded.get("boltwatch.StopDecision", []) if d["run_id"] == run_id]
    t0_ns = samples[0]["time_ns"]

    def seconds(time_ns: int) -> float:
        return (time_ns - t0_ns) / 1e9

    figure, torque_axis = plt.subplots(figsize=(10, 5), dpi=100)
    time_s = [seconds(s["time_ns"]) for s in samples]
    torque_axis.plot(time_s, [s["torque_nm"] for s in samples], color="tab:blue", lw=0.8)
    torque_axis.set_xlabel("time since first sample (s)")
    torque_axis.set_ylabel("torque (Nm)", color="tab:blue")
    if events:
        torque_axis.plot(
            [seconds(e["time_ns"]) for e in events],
            [e["peak_torque_nm"] for e in events],
            "v",
            color="tab:red",
            label="peak torque T_max,j",
        )
    forces = [(t, s["force_n"]) for t, s in zip(time_s, samples, strict=True) if s["force_n"]]
    if forces:
        force_axis = torque_axis.twinx()
        force_axis.plot(*zip(*forces, strict=True), color="tab:green", lw=0.8)
        force_axis.set_ylabel("preload force (N)", color="tab:green")
        plateaus = [e for e in events if e["plateau_force_n"] is not None]
        if plateaus:
            force_axis.plot(
                [seconds(e["time_ns"]) for e in plateaus],
                [e["plateau_force_n"] for e in plateaus],
                "_",
                ms=14,
                mew=2,
                color="black",
                label="plateau F_j",
            )
            force_axis.legend(loc="lower right")
    for decision in decisions:
        torque_axis.axvline(seconds(decision["time_ns"]), color="gray", ls="--", lw=1)
    if events:
        torque_axis.legend(loc="upper left")
    state = "" if scan.complete else " (damaged file: readable part)"
    torque_axis.set_title(f"{source.name}: run {run_id}, {len(events)} stick-slip events{state}")
    figure.tight_layout()
    figure.savefig(target)
    plt.close(figure)
    return len(samples), len(events)
