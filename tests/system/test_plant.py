"""A plant of two lines: meshed routers, a recorder per line, status and wear from any line.

Each line server runs its router, its recorder for its own station, and the
station (acquisition with its edge predictor, simulated rig); line 2's router
connects to line 1's. Checked: each recorder's MCAP holds its own station
only (the other line's samples never reach it, nor are they counted as bad
payloads); ``boltwatch status`` on line 1 shows line 2's station with its
services and its recorder's health; ``boltwatch wear --plant`` on line 1 (and
on line 2) merges both ledgers for the tool that worked on both lines.

Once on this host's loopback (two router ports: runs anywhere) and once with
each line server in its own network namespace, the two joined by a veth pair
(skipped, with the reason, where namespaces cannot be made).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.support.live_recorder import wait_until
from tests.support.netns_line import unavailable_reason
from tests.support.plant import (
    LINES,
    PLANT,
    TOOL_ID,
    Hosts,
    LoopbackPlant,
    NamespacePlant,
    Plant,
    recorded_topics,
)
from tests.support.router_process import boltwatch

pytestmark = pytest.mark.system

RUNS = 2
WHY_NO_NAMESPACES = unavailable_reason()


@pytest.fixture
def namespaces() -> Iterator[NamespacePlant]:
    if WHY_NO_NAMESPACES is not None:
        pytest.skip(WHY_NO_NAMESPACES)
    with NamespacePlant() as hosts:
        yield hosts


def test_two_lines_on_loopback_into_one_postgresql(tmp_path: Path, postgres_url: str) -> None:
    """Both lines' recorders write the plant's results store; ``results`` and ``report``
    answer for either line and across both."""
    run_plant(LoopbackPlant(), tmp_path, postgres_url)
    stations = [str(tmp_path / f"line{line}" / "station.toml") for line in LINES]
    for line in LINES:
        found = _results("--database", postgres_url, "--plant", PLANT, "--line", f"line{line}")
        assert [
            (row["station"], row["plant"], row["line"], row["station_name"]) for row in found
        ] == [(f"st{line}", PLANT, f"line{line}", f"Station {line}")] * RUNS
    across = _results("--config", *stations)
    assert sorted(row["station"] for row in across) == ["st1"] * RUNS + ["st2"] * RUNS
    report = boltwatch("report", "--config", *stations, "--out", str(tmp_path / "report"))
    assert report.returncode == 0, report.stdout + report.stderr
    assert f"{2 * RUNS} results (from the results store postgresql://" in report.stdout
    line_2 = boltwatch(
        "report", "--config", *stations, "--plant", PLANT, "--line", "line2", "--out", str(tmp_path)
    )
    assert f"{RUNS} results (from the results store postgresql://" in line_2.stdout, line_2


def test_two_lines_in_network_namespaces(namespaces: NamespacePlant, tmp_path: Path) -> None:
    run_plant(namespaces, tmp_path)


def _results(*arguments: str) -> list[dict[str, Any]]:
    """``boltwatch results ARGUMENTS --json`` (none matching, or no store yet: [])."""
    found = boltwatch("results", *arguments, "--json")
    assert found.returncode in (0, 1), found.stdout + found.stderr
    rows: list[dict[str, Any]] = json.loads(found.stdout or "[]")
    return rows


def run_plant(hosts: Hosts, folder: Path, results_database: str | None = None) -> None:
    plant = Plant(hosts, folder, results_database)
    try:
        plant.start_lines()
        plant.wait_until_up()
        for rig in plant.start_rigs(RUNS):
            assert rig.wait(60) == 0, f"a rig failed; see {plant.logs}"
        status = _settled_status(plant)
        wear = {line: plant.wear(line) for line in LINES}
        if results_database is not None:  # every result of the lines in the plant's store
            wait_until(
                lambda: len(_results("--database", results_database)) == 2 * RUNS,
                "both lines' results in the plant's store",
                30.0,
            )
    finally:
        plant.stop()

    # status on line 1: line 2's station, its services, its recorder (line 2's) healthy
    assert sorted(status) == ["st1", "st2"], status
    for line in LINES:
        station = status[f"st{line}"]
        assert all(station["services"][s] for s in ("acquisition", "predictor", "recorder"))
        recorder = station["recorder"]
        assert recorder is not None, station
        # its station file's [station] plant, line and name
        place = (recorder["plant"], recorder["line"], recorder["station_name"])
        assert place == (PLANT, f"line{line}", f"Station {line}"), recorder
        assert recorder["recording"] and recorder["bad_payloads"] == 0, recorder
        assert recorder["missing_samples"] == 0, recorder
    # wear from either line: the tool's runs on both lines, from both ledgers
    for line in LINES:
        (tool,) = wear[line]
        assert tool["tool_id"] == TOOL_ID
        assert tool["stations"] == ["st1", "st2"], tool
        assert tool["runs"] == 2 * RUNS, tool
        assert {run["station"] for run in tool["worst_runs"]} <= {"st1", "st2"}
    # each line's recordings: its own station only, every topic of it
    for line in LINES:
        topics = recorded_topics(plant.recordings(line))
        own = f"boltwatch/st{line}/"
        assert topics and all(topic.startswith(own) for topic in topics), sorted(topics)
        for topic in ("samples", "runs", "tool", "bus", "decision"):
            assert topics.get(own + topic, 0) > 0, (own + topic, sorted(topics))
        folders = sorted(path.name for path in plant.recordings(line).iterdir() if path.is_dir())
        assert folders == [".parts", ".spool", f"st{line}"], folders
        # the spool folder (the station's spools, the recorder's filing state) and the last
        # parts the recorder keeps: its own station's
        spooled = sorted(path.name for path in (plant.recordings(line) / ".spool").iterdir())
        assert spooled and all(name.startswith(f"st{line}-") for name in spooled), spooled
        parts = sorted(path.name for path in (plant.recordings(line) / ".parts").iterdir())
        assert parts == [f"st{line}.json"], parts


def _settled_status(plant: Plant) -> dict[str, Any]:
    """Status on line 1 once both recorders report every sample of their station recorded
    (the last BusStats counts the samples the acquisition published)."""
    status: dict[str, Any] = {}
    for _attempt in range(10):
        status = plant.status(1)
        recorders = [
            station.get("recorder") for station in status.values() if isinstance(station, dict)
        ]
        if len(recorders) == len(LINES) and all(
            isinstance(r, dict) and r["missing_samples"] == 0 and r["messages"] > 0
            for r in recorders
        ):
            return status
    return status
