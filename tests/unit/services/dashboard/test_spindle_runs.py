"""A multi-spindle station's runs on the line's page over real HTTP (the dashboard's aiohttp app
on a free port of 127.0.0.1), read from cycles the real recorder wrote (one file per cycle,
named by its first spindle's run) and a real results store filled from them: a spindle's run
whose file is named by another run of its cycle is found and drawn as its recording holds it
(read back with mcap's own reader); its cycle's runs overlaid, in spindle order, with the
cycle's common result; the part search's rows say each run's spindle, sync id and its cycle's
common result; a single-spindle station's run has no cycle to overlay."""

from __future__ import annotations

import asyncio
import json
import sqlite3
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from aiohttp.test_utils import TestServer
from mcap.reader import make_reader

from services.dashboard.line_board import LineBoard, StationSetting
from services.dashboard.part_search import PartSearch, stores_of
from services.dashboard.run_locator import RunLocator, StationRecordings
from services.dashboard.run_views import RunViews
from services.dashboard.web_app import Listeners, make_app
from shared.config import AnyStation, load_any_station
from tests.benchmarks.run_recordings import record_runs
from tests.support import factories
from tests.support.recorded_cycles import NOK_REASON, NOK_SPINDLE, SYNC, cycle_runs, record_cycles

SPINDLES = 4
SAMPLES = 300


@pytest.fixture(scope="module")
def station(tmp_path_factory: pytest.TempPathFactory) -> AnyStation:
    folder = tmp_path_factory.mktemp("cycles")
    return load_any_station(record_cycles(folder, cycles=2, spindles=SPINDLES, samples=SAMPLES))


def _ask(station: AnyStation, *paths: str) -> list[tuple[int, Any]]:
    """Each of ``paths`` asked of the page's app for ``station``: (status, JSON body)."""

    async def ask() -> list[tuple[int, Any]]:
        views = RunViews(RunLocator([StationRecordings.of(station)]))
        board = LineBoard([StationSetting("st1", None)], factories.T0)
        app = make_app(board, Listeners(), PartSearch(stores_of([station])), views=views)
        answers = []
        async with TestServer(app, host="127.0.0.1") as server, aiohttp.ClientSession() as client:
            for path in paths:
                async with client.get(str(server.make_url(path))) as response:
                    answers.append((response.status, json.loads(await response.read())))
        return answers

    return asyncio.run(ask())


def _recorded(path: Path) -> dict[int, list[dict[str, Any]]]:
    """Each run's samples in the cycle's file, read with mcap's own reader."""
    runs: dict[int, list[dict[str, Any]]] = {}
    with path.open("rb") as handle:
        for _, _, message in make_reader(handle).iter_messages(["boltwatch/st1/samples"]):
            sample = json.loads(message.data)
            runs.setdefault(sample["run_id"], []).append(sample)
    return runs


def test_a_spindle_s_run_in_its_cycle_s_file_is_drawn_as_recorded(station: AnyStation) -> None:
    first, _, third, _ = cycle_runs(1, SPINDLES)
    (cycle_file,) = station.recordings_folder.glob(f"st1/*/st1_run{first}_*.mcap")
    ((status, view),) = _ask(station, f"/api/runs/st1/{third}")
    assert status == 200, view
    recorded = _recorded(cycle_file)[third]
    assert view["samples"] == len(recorded) == SAMPLES
    assert view["series"]["torque_nm"] == [s["torque_nm"] for s in recorded]
    assert view["files"] == [cycle_file.name]
    assert (view["result"]["spindle"], view["result"]["sync_id"]) == (NOK_SPINDLE, SYNC + 1)
    assert view["stored"]["cycle"]["result"] == "NOK"
    assert view["stored"]["cycle"]["nok_reasons"] == f"spindle {NOK_SPINDLE} NOK ({NOK_REASON})"


def test_a_spindle_s_run_with_its_cycle_s_runs_overlaid_in_spindle_order(
    station: AnyStation,
) -> None:
    runs = cycle_runs(1, SPINDLES)
    (cycle_file,) = station.recordings_folder.glob(f"st1/*/st1_run{runs[0]}_*.mcap")
    recorded = _recorded(cycle_file)
    ((status, cycle),) = _ask(station, f"/api/runs/st1/{runs[2]}/cycle?align=start")
    assert status == 200, cycle
    assert [r["key"] for r in cycle["runs"]] == [f"st1/{run}" for run in runs]
    assert [r["spindle"] for r in cycle["runs"]] == [1, 2, 3, 4]
    assert [r["reference"] for r in cycle["runs"]] == [False, False, True, False]
    assert [r["verdict"] for r in cycle["runs"]] == ["OK", "OK", "NOK", "OK"]
    for run, drawn in zip(runs, cycle["runs"], strict=True):
        assert drawn["samples"] == len(recorded[run]) == SAMPLES
        assert drawn["torque_nm"][-1] == recorded[run][-1]["torque_nm"]
    assert cycle["cycle"] == {
        "sync_id": SYNC + 1,
        "spindles": SPINDLES,
        "result": "NOK",
        "nok_reasons": f"spindle {NOK_SPINDLE} NOK ({NOK_REASON})",
        "part_id": "P1",
    }
    assert cycle["left_out"] == []


def test_the_part_search_says_each_row_s_spindle_and_its_cycle(station: AnyStation) -> None:
    ((status, found),) = _ask(station, "/api/results?part=P1")
    assert status == 200
    rows = found["results"]
    assert sorted((r["spindle"], r["run_id"]) for r in rows) == list(
        zip([1, 2, 3, 4], cycle_runs(1, SPINDLES), strict=True)
    )
    assert {r["sync_id"] for r in rows} == {SYNC + 1}
    assert {(r["cycle"]["result"], r["cycle"]["nok_reasons"]) for r in rows} == {
        ("NOK", f"spindle {NOK_SPINDLE} NOK ({NOK_REASON})")
    }


def test_a_single_spindle_station_s_run_has_no_cycle_to_overlay(tmp_path: Path) -> None:
    record_runs(tmp_path, 2, 200)
    single = load_any_station(tmp_path / "station.toml")
    from shared.results import ResultsStore, store_target
    from shared.results.recordings_reading import fill_from_recordings, station_recordings

    with ResultsStore(store_target(single.recordings_folder, None)) as store:
        files = station_recordings(single.recordings_folder, ["st1"])
        fill_from_recordings(store, files, {}, "line", lambda: factories.T0)
    (status, view), (cycle_status, body), (_, found) = _ask(
        single, "/api/runs/st1/1", "/api/runs/st1/1/cycle", "/api/results?part=L1-P0000000"
    )
    assert status == 200
    assert (view["result"]["spindle"], view["result"]["sync_id"]) == (None, None)
    assert "cycle" not in view["stored"]
    assert cycle_status == 404
    assert body["errors"] == [
        "run 1 of st1 is not a spindle's run of a multi-spindle cycle: no cycle to overlay"
    ]
    assert found["results"] and all(
        not {"spindle", "sync_id", "cycle"} & set(row) for row in found["results"]
    )


def test_a_spindle_s_run_whose_row_names_no_run_file_of_the_station_is_never_read(
    tmp_path: Path,
) -> None:
    hostile = load_any_station(record_cycles(tmp_path, cycles=1, spindles=2, samples=50))
    folder = hostile.recordings_folder.resolve()
    with sqlite3.connect(folder / "results.sqlite") as database:
        database.execute("UPDATE tightenings SET recording = '/etc/passwd' WHERE run_id = 5001")
    (status, body), (_, cycle) = _ask(hostile, "/api/runs/st1/5001", "/api/runs/st1/5001/cycle")
    assert status == 404 and cycle == body
    assert body["errors"] == [
        f"run 5001 of st1: the results store names /etc/passwd, outside the station's "
        f"recordings folder {folder}: not read"
    ]
