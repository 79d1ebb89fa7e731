"""The page's part search over real HTTP (the dashboard's aiohttp app on a free port of
127.0.0.1) on real results stores: a part's tightenings newest first with their
recordings, a part with none, hostile and oversized questions, stores that are not
there or do not answer (the page's board still answers meanwhile), the stores of
the station files."""

from __future__ import annotations

import asyncio
import contextlib
import socket
import time
from collections.abc import AsyncIterator, Iterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from aiohttp.test_utils import TestServer

from services.dashboard.line_board import LineBoard, StationSetting
from services.dashboard.part_search import MAX_LIMIT, PartSearch, stores_of
from services.dashboard.web_app import Listeners, make_app
from shared.config import load_any_station
from shared.contract import PART_ID_CHARS, JudgedFigure, TighteningResult
from shared.results import ResultsStore, StoreTarget, stored_result
from shared.results import results_database as results_database_module
from tests.support import factories
from tests.support.station_files import write_station

MINUTE_NS = 60_000_000_000
VIN = "WVWZZZ1JZXW000001"
HOSTILE = "<img src=x onerror=alert(1)><script>alert(2)</script>"


def _result(run_id: int, part_id: str, minute: int, **changes: Any) -> TighteningResult:
    return factories.result(
        run_id, part_id=part_id, time_ns=factories.T0 + minute * MINUTE_NS, **changes
    )


def _fill(path: Path, *results: TighteningResult, line: str = "A") -> StoreTarget:
    target = StoreTarget(sqlite_path=path)
    with ResultsStore(target) as store:
        store.add(
            [
                stored_result(r, line, f"/rec/{r.station}/run{r.run_id}.mcap", "box", 1)
                for r in results
            ]
        )
    return target


@contextlib.asynccontextmanager
async def _served(*targets: StoreTarget) -> AsyncIterator[tuple[aiohttp.ClientSession, str]]:
    """The dashboard's app on a free port, and a client of it."""
    board = LineBoard([StationSetting("st1", None)], factories.T0)
    app = make_app(board, Listeners(), PartSearch(targets))
    async with TestServer(app, host="127.0.0.1") as server, aiohttp.ClientSession() as client:
        yield client, str(server.make_url(""))


async def _get(
    client: aiohttp.ClientSession, url: str, **query: str
) -> tuple[int, dict[str, Any], aiohttp.ClientResponse]:
    async with client.get(f"{url}/api/results", params=query) as response:
        return response.status, await response.json(), response


def _ask(*targets: StoreTarget, **query: str) -> tuple[int, dict[str, Any]]:
    async def ask() -> tuple[int, dict[str, Any]]:
        async with _served(*targets) as (client, url):
            status, body, _ = await _get(client, url, **query)
            return status, body

    return asyncio.run(ask())


@pytest.fixture
def store(tmp_path: Path) -> StoreTarget:
    """A SQLite store of three tightenings of :data:`VIN` at two stations (one NOK) and
    one of another part."""
    return _fill(
        tmp_path / "recordings" / "results.sqlite",
        _result(1, VIN, 1),
        _result(
            2,
            VIN,
            3,
            result="NOK",
            nok_reasons="preload low",
            final_force_n=JudgedFigure(51200.0, 53000.0, 59000.0, "low"),
        ),
        _result(1, VIN, 2, station="st2", tool_id=8),
        _result(3, "other part", 4),
    )


def test_a_part_s_tightenings_newest_first_with_where_each_recording_is(
    store: StoreTarget,
) -> None:
    status, body = _ask(store, part=f"  {VIN} ")  # a pasted id's spaces are not part of it
    assert status == 200 and body["errors"] == [] and body["answered"] is True
    assert body["part_id"] == VIN and body["total"] == 3 and body["stores"] == [str(store)]
    found = body["results"]
    assert [(r["station"], r["run_id"]) for r in found] == [("st1", 2), ("st2", 1), ("st1", 1)]
    nok = found[0]
    assert (nok["result"], nok["nok_reasons"]) == ("NOK", "preload low")
    assert nok["final_force_n"] == {"value": 51.2e3, "min": 53e3, "max": 59e3, "status": "low"}
    assert nok["ended_utc"] == "2023-11-14 22:16:20"  # T0 (1.7e9 s) and 3 minutes
    assert (nok["line"], nok["recording"], nok["recording_host"]) == (
        "A",
        "/rec/st1/run2.mcap",
        "box",
    )
    assert (nok["stop_reason"], nok["events"], nok["program_id"], nok["program_name"]) == (
        "plateau_closest",
        9,
        1,
        "M14 to 56 kN",
    )
    assert found[1]["tool_id"] == 8
    # bounded: the newest of them, and how many there are
    status, body = _ask(store, part=VIN, limit="2")
    assert status == 200 and body["total"] == 3 and body["limit"] == 2
    assert [(r["station"], r["run_id"]) for r in body["results"]] == [("st1", 2), ("st2", 1)]


def test_a_part_with_no_tightening_is_an_empty_answer(store: StoreTarget) -> None:
    status, body = _ask(store, part="VIN-NEVER-SEEN")
    assert status == 200 and body["answered"] is True
    assert (body["results"], body["total"], body["errors"]) == ([], 0, [])


def test_hostile_part_ids_are_data_and_long_ones_are_refused(store: StoreTarget) -> None:
    async def ask() -> None:
        async with _served(store) as (client, url):
            for part_id in (HOSTILE, "' OR '1'='1", "x' OR 1=1; DROP TABLE tightenings; --"):
                status, body, response = await _get(client, url, part=part_id)
                assert status == 200 and body["part_id"] == part_id and body["results"] == []
                assert response.content_type == "application/json"
                assert response.headers["X-Content-Type-Options"] == "nosniff"
            status, body, _ = await _get(client, url, part="x" * (PART_ID_CHARS + 1))
            assert (status, body["errors"]) == (
                400,
                [f"a part id has at most {PART_ID_CHARS} characters; this one has 101"],
            )
            for query in ({}, {"part": "   "}):
                status, body, _ = await _get(client, url, **query)
                assert status == 400 and body["errors"][0].startswith("type a part id")
            for limit in ("0", str(MAX_LIMIT + 1), "-1", "ten", "1e3", "²", "0" * 5000):
                status, body, _ = await _get(client, url, part=VIN, limit=limit)
                assert status == 400
                assert body["errors"][0].startswith(f"limit: a number from 1 to {MAX_LIMIT}")
            # the store is whole: the part still has its three
            status, body, _ = await _get(client, url, part=VIN)
            assert status == 200 and body["total"] == 3

    asyncio.run(ask())


def test_a_store_not_there_is_one_line_and_is_not_made(tmp_path: Path) -> None:
    missing = StoreTarget(sqlite_path=tmp_path / "recordings" / "results.sqlite")
    status, body = _ask(missing, part=VIN)
    assert status == 503 and body["answered"] is False and body["results"] == []
    assert body["errors"] == [
        f"no results store at {missing}: the line's recorder makes it, "
        "'boltwatch results rebuild' fills it from existing recordings"
    ]
    assert not (tmp_path / "recordings").exists()


def test_each_store_of_the_line_is_searched_and_one_missing_leaves_the_others(
    tmp_path: Path, store: StoreTarget
) -> None:
    other = _fill(
        tmp_path / "other" / "results.sqlite", _result(5, VIN, 9, station="st3"), line="B"
    )
    missing = StoreTarget(sqlite_path=tmp_path / "nowhere" / "results.sqlite")
    status, body = _ask(store, other, missing, part=VIN, limit="3")
    assert status == 200 and body["answered"] is True and body["total"] == 4
    assert [(r["station"], r["run_id"], r["line"]) for r in body["results"]] == [
        ("st3", 5, "B"),
        ("st1", 2, "A"),
        ("st2", 1, "A"),
    ]
    (error,) = body["errors"]
    assert error.startswith(f"no results store at {missing}")


def test_a_plant_s_postgresql_store(postgres_url: str, store: StoreTarget) -> None:
    plant = StoreTarget(postgres_url=postgres_url)
    with ResultsStore(plant) as database:
        database.add([stored_result(_result(7, VIN, 5, station="st9"), "C", None, None, 1)])
    status, body = _ask(plant, store, part=VIN)
    assert status == 200 and body["errors"] == [] and body["total"] == 4
    assert [(r["station"], r["recording"]) for r in body["results"]][:2] == [
        ("st9", None),
        ("st1", "/rec/st1/run2.mcap"),
    ]


@contextlib.contextmanager
def _silent_server() -> Iterator[str]:
    """A TCP port that takes connections and never says a word (a database server hung,
    or a firewall holding the line): the URL of a PostgreSQL there, with a password."""
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)
        yield f"postgresql://quality:secret@127.0.0.1:{listener.getsockname()[1]}/results"


def test_a_store_that_does_not_answer_holds_up_neither_the_board_nor_the_page(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(results_database_module, "CONNECT_TIMEOUT_S", 2)  # libpq's least

    async def ask(hung: StoreTarget) -> tuple[float, int, dict[str, Any]]:
        async with _served(hung) as (client, url):
            search = asyncio.ensure_future(_get(client, url, part=VIN))
            await asyncio.sleep(0.3)
            started_s = time.monotonic()
            async with client.get(f"{url}/board.json") as response:
                assert response.status == 200
                assert [s["station"] for s in (await response.json())["stations"]] == ["st1"]
            board_s = time.monotonic() - started_s
            assert not search.done()  # still waiting for the store
            status, body, _ = await search
            return board_s, status, body

    with _silent_server() as url:
        board_s, status, body = asyncio.run(ask(StoreTarget(postgres_url=url)))
    assert board_s < 0.5
    assert status == 503 and body["results"] == []
    (error,) = body["errors"]
    assert error.startswith("results store postgresql://quality:***@127.0.0.1:")
    assert "cannot open" in error and "secret" not in error
    assert body["stores"] == [url.replace(":secret@", ":***@")]


def test_the_stores_of_the_station_files_each_distinct_one_once(tmp_path: Path) -> None:
    def station(folder: str, station_id: str, database: str | None = None) -> Path:
        replacements = {'id = "st1"': f'id = "{station_id}"'}
        if database is not None:
            replacements["[recorder]\n"] = f'[recorder]\nresults_database = "{database}"\n'
        (tmp_path / folder).mkdir()
        return write_station(tmp_path / folder, replacements=replacements)

    plant = "postgresql://quality@db.plant/results"
    files = [
        station("a", "st1"),
        station("b", "st2"),
        station("c", "st3", plant),
        station("d", "st4", plant),
    ]
    # st2's file names the same recordings folder as st1's, by another path
    text = files[1].read_text().replace(str(tmp_path / "b"), str(tmp_path / "x" / ".." / "a"))
    files[1].write_text(text)
    targets = stores_of([load_any_station(path) for path in files])
    assert [str(t) for t in targets] == [
        str(tmp_path / "a" / "recordings" / "results.sqlite"),
        plant,
    ]
