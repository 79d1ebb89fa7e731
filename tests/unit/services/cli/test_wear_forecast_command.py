"""``boltwatch wear``: each tool's service forecast, in the table and in ``--json``."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import pytest

from services.cli.main import main
from shared.wear import CONTRACT_LIMITS, WearLedger
from tests.support import factories
from tests.support.wear_plant import TWO_SHIFTS, plant_until, write_ledger

DAY_NS = 86_400 * 1_000_000_000
YOUNG_TOOL = 900


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, float]:
    """Eight weeks of a two-shift plant up to now, and a tool that came three days ago."""
    now_ns = time.time_ns()
    plant = plant_until(replace(TWO_SHIFTS, days=56, stations=3), 4, now_ns)
    folder = tmp_path_factory.mktemp("recordings")
    write_ledger(plant, folder / "wear.sqlite")
    with WearLedger(folder / "wear.sqlite") as ledger:
        for run in range(20):
            ended_ns = now_ns - 3 * DAY_NS + run * 3_600_000_000
            summary = factories.summary(
                10_000_000 + run,
                station="st9",
                tool_id=YOUNG_TOOL,
                process_intensity=1e5,
                events=10,
                started_ns=ended_ns - 3_000_000_000,
                ended_ns=ended_ns,
            )
            ledger.add_run(summary, ended_ns, CONTRACT_LIMITS)
    return folder, plant.threshold


def test_json_gives_each_tool_its_forecast_and_the_share_of_its_wear_per_program(
    recordings: tuple[Path, float], capsys: pytest.CaptureFixture[str]
) -> None:
    folder, threshold = recordings
    args = ["wear", "--recordings", str(folder), "--threshold", str(threshold), "--json"]
    assert main(args) == 0
    tools = {tool["tool_id"]: tool for tool in json.loads(capsys.readouterr().out)}
    assert set(tools) == {100, 101, 102, YOUNG_TOOL}
    for tool_id, tool in tools.items():
        told = tool["forecast"]
        assert told["threshold"] == threshold
        assert told["runs_left"] is None or told["runs_left"] >= 0
        if told["state"] == "forecast":
            assert told["early_ns"] <= told["due_ns"] <= (told["late_ns"] or told["due_ns"])
            assert time.time_ns() - 60 * 1_000_000_000 < told["due_ns"]
            assert told["runs_left"] > 0
        else:
            assert told["due_ns"] is None and told["reason"], tool_id
        shares = [part["share"] for part in tool["wear_by"]["program"]]
        if tool["intensity_since_service"] > 0:
            assert sum(shares) == pytest.approx(1.0)
            assert shares == sorted(shares, reverse=True)
    assert all(tools[t]["forecast"]["state"] in ("forecast", "due") for t in (100, 101, 102))
    young = tools[YOUNG_TOOL]["forecast"]
    assert young["state"] == "none" and young["due_ns"] is None
    assert "days of history" in young["reason"]
    assert young["runs_left"] > 0  # its intensity per run is known from its first runs


def test_the_table_lists_the_tools_due_soonest_first(
    recordings: tuple[Path, float], capsys: pytest.CaptureFixture[str]
) -> None:
    folder, threshold = recordings
    assert main(["wear", "--recordings", str(folder), "--threshold", str(threshold)]) == 0
    out = capsys.readouterr().out
    table = out[out.index("service forecast") :].splitlines()
    assert table[0] == f"service forecast (UTC), threshold {threshold:.4g}"
    order = [int(line.split()[0]) for line in table[2:] if line[:1].isdigit()]
    assert order[-1] == YOUNG_TOOL  # no date: last
    assert "days of history" in table[2 + order.index(YOUNG_TOOL)]


def test_no_threshold_says_so_instead_of_a_date(
    recordings: tuple[Path, float], capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder, _ = recordings
    args = ["wear", "--recordings", str(folder), "--config", str(tmp_path / "none.toml")]
    assert main([*args, "--json"]) == 0
    tools = json.loads(capsys.readouterr().out)
    assert {tool["forecast"]["state"] for tool in tools} == {"none"}
    assert all("threshold" in tool["forecast"]["reason"] for tool in tools)
    with pytest.raises(SystemExit) as refused:
        main([*args, "--threshold", "0"])
    assert refused.value.code == 2
    assert "--threshold" in capsys.readouterr().err
