"""A run's curve on the line's page over real HTTP (the dashboard's aiohttp app on a free port
of 127.0.0.1), read from recordings the real recorder wrote and a real results store
(``results rebuild``'s filling): the view's figures are the recording's, read once until its
file changes; a file being written, a run not stored yet, a damaged or broken file, each
said in words; what is not a run never served (a store row naming a file outside the
recordings folder, a link out of it, a name that is not one of the run's files); the run's
files and the outside viewers' access to them; a part's runs and a program's band; a flood
of requests bounded while the board still answers; the line's NOK list."""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import sqlite3
import threading
import time
from collections.abc import AsyncIterator, Sequence
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
from services.dashboard.viewer_links import ViewerLinks
from services.dashboard.web_app import Listeners, make_app
from shared.config import AnyStation, load_any_station
from shared.offline.post_mortem import RecordedRun, read_run_files
from shared.recordings import rerun_path, writing_path
from shared.results import ResultsStore, StoreTarget, store_target, stored_result
from shared.results.recordings_reading import fill_from_recordings, station_recordings
from tests.benchmarks.run_recordings import record_runs
from tests.support import factories

RUNS = 6
SAMPLES = 400
FOXGLOVE = "https://app.foxglove.dev/~/view?ds=remote-file&ds.url={url}"
#: a failure past it, not a figure
WAIT_S = 30.0


def _line(folder: Path) -> AnyStation:
    """Six runs of st1 (parts of 4-5 bolts: runs 1-4 one part, 5-6 the next) recorded by
    the real recorder, their results in the store as ``results rebuild`` puts them."""
    recordings = record_runs(folder, RUNS, SAMPLES)
    station = load_any_station(folder / "station.toml")
    with ResultsStore(store_target(recordings, None)) as store:
        files = station_recordings(recordings, ["st1"])
        fill_from_recordings(store, files, {}, "line-server", time.time_ns)
    return station


@pytest.fixture
def station(tmp_path: Path) -> AnyStation:
    return _line(tmp_path)


def _file(station: AnyStation, run_id: int) -> Path:
    (path,) = station.recordings_folder.glob(f"st1/*/st1_run{run_id}_*.mcap")
    return path


def _store_says(station: AnyStation, sql: str, *parameters: Any) -> None:
    """A row of the store changed by hand (as a hostile or broken store would hold it)."""
    with sqlite3.connect(station.recordings_folder / "results.sqlite") as database:
        database.execute(sql, parameters)


@contextlib.asynccontextmanager
async def _served(
    station: AnyStation, views: RunViews | None = None, links: ViewerLinks | None = None
) -> AsyncIterator[tuple[aiohttp.ClientSession, str, RunViews]]:
    """The dashboard's app for ``station`` on a free port, and a client of it."""
    links = links or ViewerLinks()
    if views is None:
        locator = RunLocator([StationRecordings.of(station)])
        views = RunViews(locator, viewers=links.as_dict())
    board = LineBoard([StationSetting("st1", None)], factories.T0)
    app = make_app(board, Listeners(), PartSearch(stores_of([station])), views=views, links=links)
    async with TestServer(app, host="127.0.0.1") as server, aiohttp.ClientSession() as client:
        yield client, str(server.make_url("")), views


async def _get(
    client: aiohttp.ClientSession, url: str, **headers: str
) -> tuple[int, Any, aiohttp.ClientResponse]:
    async with client.get(url, headers=headers) as response:
        body = await response.read()
        try:
            return response.status, json.loads(body), response
        except ValueError:
            return response.status, body, response


def _samples(path: Path, run_id: int) -> list[dict[str, Any]]:
    with path.open("rb") as handle:
        messages = make_reader(handle).iter_messages(["boltwatch/st1/samples"])
        return [s for s in (json.loads(m.data) for _, _, m in messages) if s["run_id"] == run_id]


def test_a_run_s_view_is_its_recording_read_once_until_its_file_changes(
    station: AnyStation,
) -> None:
    path = _file(station, 3)
    samples = _samples(path, 3)
    with ResultsStore(store_target(station.recordings_folder, None), create=False) as store:
        (stored,) = store.find(store_query(3))

    async def ask() -> None:
        async with _served(station) as (client, url, views):
            status, view, response = await _get(client, f"{url}/api/runs/st1/3")
            assert status == 200 and response.headers["Content-Encoding"] == "gzip"
            assert response.headers["Cache-Control"] == "no-store"
            assert view["samples"] == view["drawn"] == len(samples) == SAMPLES
            assert view["series"]["torque_nm"] == [s["torque_nm"] for s in samples]
            assert view["series"]["force_n"] == [s["force_n"] for s in samples]
            for figure in ("final_torque_nm", "final_angle_deg", "final_force_n"):
                assert view["result"][figure] == view["stored"][figure]
            assert view["result"]["final_torque_nm"]["value"] == stored.result.final_torque_nm.value
            assert view["found"] == {
                "recording": str(path.resolve()),
                "recording_host": "line-server",
                "note": "",
                "writing": False,
            }
            assert view["downloads"] == [
                {"name": path.name, "kind": "mcap", "bytes": path.stat().st_size}
            ]
            assert (views.cache.hits, views.cache.misses) == (0, 1)
            again = await _get(client, f"{url}/api/runs/st1/3", **{"Accept-Encoding": "identity"})
            assert again[0] == 200 and "Content-Encoding" not in again[2].headers
            assert again[1] == view and (views.cache.hits, views.cache.misses) == (1, 1)
            os.utime(path, ns=(time.time_ns(), time.time_ns()))  # the file changed: read again
            assert (await _get(client, f"{url}/api/runs/st1/3"))[1] == view
            assert (views.cache.hits, views.cache.misses) == (1, 2)

    asyncio.run(ask())


def store_query(run_id: int) -> Any:
    from shared.results import ResultsQuery

    return ResultsQuery(stations=["st1"], run_id=run_id)


def test_a_file_being_written_and_a_run_not_stored_yet_are_found_by_the_folder(
    station: AnyStation,
) -> None:
    newest = _file(station, 6)
    newest.rename(writing_path(newest))  # the recorder still writes it
    _store_says(station, "DELETE FROM tightenings WHERE run_id = 5")  # not stored yet
    ended = _file(station, 4)  # just ended: its samples still in the recorder's open chunk
    ended.rename(writing_path(ended))
    writing_path(ended).write_bytes(writing_path(ended).read_bytes()[:1200])
    _store_says(station, "DELETE FROM tightenings WHERE run_id = 4")

    async def ask() -> None:
        async with _served(station) as (client, url, _):
            status, view, _ = await _get(client, f"{url}/api/runs/st1/6")
            assert status == 200 and view["found"]["writing"] is True
            assert view["files"] == [writing_path(newest).name] and view["samples"] == SAMPLES
            status, view, _ = await _get(client, f"{url}/api/runs/st1/5")
            assert status == 200 and view["stored"] is None
            assert view["found"]["note"] == "not in the results store yet: found by the folder"
            assert view["result"]["run_id"] == 5  # the recording's own result
            status, body, _ = await _get(client, f"{url}/api/runs/st1/4")
            assert status == 404 and body["pending"] is True  # the page asks again
            assert body["errors"][0].startswith(
                "run 4 of st1: the recorder is still writing its file, which holds none of its "
                "samples yet"
            )
            status, body, _ = await _get(client, f"{url}/api/runs/st1/99")
            assert status == 404 and body["pending"] is True
            assert body["errors"] == [
                f"run 99 of st1: not in the results store, no file of it in "
                f"{station.recordings_folder.resolve()}"
            ]

    asyncio.run(ask())


def test_what_is_not_a_run_is_never_served(station: AnyStation, tmp_path: Path) -> None:
    folder = station.recordings_folder.resolve()
    _store_says(station, "UPDATE tightenings SET recording = '/etc/passwd' WHERE run_id = 2")
    sqlite_file = str(folder / "results.sqlite")
    _store_says(station, "UPDATE tightenings SET recording = ? WHERE run_id = 3", sqlite_file)
    outside = tmp_path / "outside.mcap"
    _file(station, 1).rename(outside)  # a run file that is a link out of the folder
    (_file_dir := folder / "st1" / "2026-07-01").joinpath("st1_run1_000000.mcap").symlink_to(
        outside
    )
    gone = _file(station, 4)
    gone.unlink()  # removed by the retention policy (or by hand)

    async def ask() -> None:
        async with _served(station) as (client, url, views):
            answers = {}
            for path in (
                "/api/runs/st9/1", "/api/runs/st1/x", "/api/runs/st1/9999999999999999999",
                "/api/runs/st1/123456789012345678901", "/api/runs/st1/2",
                "/api/runs/st1/2/files/passwd", "/api/runs/st1/3", "/api/runs/st1/1",
                "/api/runs/st1/4", "/api/runs/st1/5/files/..%2F..%2Fstation.toml",
                "/api/runs/st1/5/files/results.sqlite",
            ):  # fmt: skip
                status, body, response = await _get(client, url + path)
                assert response.headers["Content-Type"].startswith("application/json"), path
                answers[path] = (status, body["errors"][0])
            assert views.cache.misses == 0  # not one of them was read

        def said(path: str) -> tuple[int, str]:
            return answers[path]

        assert said("/api/runs/st9/1") == (
            404, "station st9 is not one of this page's stations (st1)"
        )  # fmt: skip
        assert said("/api/runs/st1/x")[0] == 400
        assert said("/api/runs/st1/123456789012345678901")[0] == 400
        assert said("/api/runs/st1/9999999999999999999") == (
            400, "a run id is at most 9223372036854775807 (got 9999999999999999999)"
        )  # fmt: skip
        assert said("/api/runs/st1/2") == (
            404,
            "run 2 of st1: the results store names /etc/passwd, outside the station's "
            f"recordings folder {folder}: not read",
        )
        assert said("/api/runs/st1/2/files/passwd") == said("/api/runs/st1/2")
        assert said("/api/runs/st1/3") == (
            404,
            f"run 3 of st1: the results store names {sqlite_file}, which is not a file of the "
            f"run in {folder}: not read",
        )
        assert said("/api/runs/st1/1") == (
            404,
            f"run 1 of st1: {_file_dir / 'st1_run1_000000.mcap'} leads outside the station's "
            f"recordings folder {folder} (to {outside.resolve()}): not read",
        )
        assert said("/api/runs/st1/4") == (
            404,
            f"run 4 of st1: the results store names {gone.resolve()} (recorded on "
            "line-server), which is not on this server: the retention policy may have "
            "removed it",
        )
        name = _file(station, 5).name
        assert said("/api/runs/st1/5/files/..%2F..%2Fstation.toml") == (
            404, f"'../../station.toml' is not a file of run 5 of st1 (its files: {name})"
        )  # fmt: skip
        assert said("/api/runs/st1/5/files/results.sqlite")[0] == 404

    asyncio.run(ask())


def test_a_damaged_recording_is_drawn_as_far_as_it_reads_and_a_broken_one_is_said(
    station: AnyStation,
) -> None:
    damaged = _file(station, 2)  # its tail cut off (its summary and footer)
    damaged.write_bytes(damaged.read_bytes()[: damaged.stat().st_size * 7 // 10])
    cut = _file(station, 4)  # cut inside the samples' chunk: nothing of the run left
    cut.write_bytes(cut.read_bytes()[: cut.stat().st_size * 3 // 10])
    broken = _file(station, 3)
    broken.write_bytes(b"\x00" * 4096)

    async def ask() -> None:
        async with _served(station) as (client, url, _):
            status, view, _ = await _get(client, f"{url}/api/runs/st1/2")
            assert status == 200 and view["complete"] is False and view["samples"] == SAMPLES
            assert "bytes lost" in view["state"]
            status, body, _ = await _get(client, f"{url}/api/runs/st1/4")
            assert status == 422
            assert body["errors"][0].startswith(
                f"run 4 of st1: {cut.resolve()}: no samples to plot (damaged record after byte"
            )
            status, body, _ = await _get(client, f"{url}/api/runs/st1/3")
            assert status == 422
            assert body["errors"][0].startswith(f"run 3 of st1: {broken.resolve()}: not an MCAP")

    asyncio.run(ask())


def test_the_run_s_files_download_and_only_the_named_viewers_read_them_across_origins(
    station: AnyStation,
) -> None:
    path = _file(station, 1)
    rerun_path(path).write_bytes(b"rerun data " * 100)
    links = ViewerLinks(foxglove=FOXGLOVE)
    viewer, stranger = "https://app.foxglove.dev", "https://pages.example"

    async def ask() -> None:
        async with _served(station, links=links) as (client, url, _):
            status, view, _ = await _get(client, f"{url}/api/runs/st1/1")
            assert status == 200 and view["viewers"] == {"rerun": None, "foxglove": FOXGLOVE}
            assert [(d["name"], d["kind"]) for d in view["downloads"]] == [
                (path.name, "mcap"), (rerun_path(path).name, "rrd")
            ]  # fmt: skip
            files = f"{url}/api/runs/st1/1/files"
            status, body, response = await _get(client, f"{files}/{path.name}", Origin=viewer)
            assert status == 200 and body == path.read_bytes()
            assert response.headers["Content-Disposition"] == f'attachment; filename="{path.name}"'
            assert response.headers["Access-Control-Allow-Origin"] == viewer
            status, body, response = await _get(client, f"{files}/{path.name}", Origin=stranger)
            assert status == 200 and "Access-Control-Allow-Origin" not in response.headers
            status, body, _ = await _get(
                client, f"{files}/{rerun_path(path).name}", Range="bytes=0-9"
            )
            assert (status, body) == (206, b"rerun data")
            for origin, expected in ((viewer, 204), (stranger, 403)):
                headers = {"Origin": origin, "Access-Control-Request-Method": "GET"}
                async with client.options(f"{files}/{path.name}", headers=headers) as response:
                    assert response.status == expected
                    allowed = response.headers.get("Access-Control-Allow-Origin")
                    assert allowed == (viewer if expected == 204 else None)

    asyncio.run(ask())


def test_a_part_s_runs_overlaid_and_a_run_against_its_program_s_recent_runs(
    station: AnyStation,
) -> None:
    async def ask() -> None:
        async with _served(station) as (client, url, _):
            status, part, _ = await _get(client, f"{url}/api/runs/st1/3/part")
            assert status == 200 and part["part_id"] == "L1-P0000000" and part["total"] == 4
            assert [(r["key"], r["reference"]) for r in part["runs"]] == [
                ("st1/4", False), ("st1/3", True), ("st1/2", False), ("st1/1", False)
            ]  # fmt: skip
            assert all(r["samples"] == SAMPLES for r in part["runs"])
            assert part["windows"][0]["torque_nm"] == [180.0, 240.0]
            status, band, _ = await _get(client, f"{url}/api/runs/st1/6/program?runs=3")
            assert status == 200 and band["runs"] == ["st1/5", "st1/4", "st1/3"]
            assert band["program"] == {"id": 1, "name": "M14 to 56 kN"} and band["asked"] == 3
            assert band["over_angle"]["torque_nm"]["low"][0] is not None
            for path, words in (
                ("program?runs=1", "runs: a number from 2 to 100 (got '1')"),
                ("program?align=middle", "align 'middle': expected start, first-slip or"),
            ):
                status, body, _ = await _get(client, f"{url}/api/runs/st1/6/{path}")
                assert status == 400 and body["errors"][0].startswith(words)

    asyncio.run(ask())


class _HeldReader:
    """Reads a run once let go (:attr:`go`), counting the readings."""

    def __init__(self) -> None:
        self.go = threading.Event()
        self.reads = 0

    def __call__(self, files: Sequence[Path], run_id: int) -> RecordedRun:
        self.reads += 1
        assert self.go.wait(WAIT_S), "never let go"
        return read_run_files(files, run_id)


def test_a_flood_of_view_requests_is_bounded_and_the_board_still_answers(
    station: AnyStation,
) -> None:
    reader = _HeldReader()
    views = RunViews(RunLocator([StationRecordings.of(station)]), readers=1, waiting=1, read=reader)

    async def ask() -> None:
        async with _served(station, views=views) as (client, url, _):
            asked = [
                asyncio.ensure_future(_get(client, f"{url}/api/runs/st1/{run}"))
                for run in range(1, RUNS + 1)
            ]
            waiting = set(asked)
            async with asyncio.timeout(WAIT_S):
                while len(asked) - len(waiting) < RUNS - 2:  # one reading, one waiting: the
                    _, waiting = await asyncio.wait(  # rest answered at once
                        waiting, return_when=asyncio.FIRST_COMPLETED
                    )
            refused = [task for task in asked if task.done()]
            for task in refused:
                status, body, response = task.result()
                assert status == 503 and response.headers["Retry-After"] == "1"
                assert body["errors"] == [
                    "the page is reading 2 runs for others: ask again in a moment"
                ]
            status, board, _ = await _get(client, f"{url}/board.json")  # the page still answers
            assert status == 200 and board["stations"][0]["station"] == "st1"
            reader.go.set()
            answered = [await task for task in asked if task not in refused]
            assert [status for status, _, _ in answered] == [200, 200]
            assert views.refused == RUNS - 2
            # several people opening one run: one reading for all of them
            reads = reader.reads
            same = [_get(client, f"{url}/api/runs/st1/6") for _ in range(5)]
            assert {status for status, _, _ in await asyncio.gather(*same)} == {200}
            assert reader.reads - reads <= 1

    asyncio.run(ask())


def test_the_line_s_nok_list_holds_its_stations_noks_newest_first(tmp_path: Path) -> None:
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    minute = 60 * factories.S
    results = [
        factories.result(1, time_ns=factories.T0 + minute),
        factories.result(2, time_ns=factories.T0 + 2 * minute, result="NOK", nok_reasons="low"),
        factories.result(3, time_ns=factories.T0 + 3 * minute, result="NOK", nok_reasons="high"),
        factories.result(4, station="st2", time_ns=factories.T0, result="NOK", nok_reasons="x"),
    ]
    with ResultsStore(target) as store:
        store.add([stored_result(r, "A", None, None, 1) for r in results])

    async def ask() -> dict[str, Any]:
        board = LineBoard([StationSetting("st1", None)], factories.T0)
        app = make_app(board, Listeners(), PartSearch([target]))
        async with TestServer(app, host="127.0.0.1") as server, aiohttp.ClientSession() as client:
            status, body, _ = await _get(client, f"{server.make_url('')}/api/noks")
            assert status == 200
            assert (await _get(client, f"{server.make_url('')}/api/noks?limit=0"))[0] == 400
            return dict(body)

    body = asyncio.run(ask())
    assert [(r["station"], r["run_id"], r["nok_reasons"]) for r in body["results"]] == [
        ("st1", 3, "high"),
        ("st1", 2, "low"),
    ]
    assert body["stations"] == ["st1"] and body["total"] == 2


def test_an_outside_viewer_is_an_http_url_with_the_file_s_place_once(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from services.cli.main import main

    for bad in ("ftp://viewer/?url={url}", "https://viewer/", "https://{url}/", "viewer?url={url}"):
        with pytest.raises(SystemExit) as exited:
            main(["serve", "dashboard", "--foxglove", bad])
        assert exited.value.code == 2
        (line,) = [x for x in capsys.readouterr().err.splitlines() if "error:" in x]
        assert line.endswith(f"(got {bad!r})")
    links = ViewerLinks(rerun="http://Line-Server:9090/?url={url}", foxglove=FOXGLOVE)
    assert links.origins == {"http://line-server:9090", "https://app.foxglove.dev"}
    assert links.allows("https://app.foxglove.dev") and not links.allows("https://app.foxglove.de")
    assert not ViewerLinks().allows("null") and not links.allows(None)
