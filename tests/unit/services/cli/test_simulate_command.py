"""``boltwatch simulate`` writes the offline trace contract."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pytest

from services.cli.commands import simulate
from shared.contract import read_trace
from shared.errors import ConfigError
from tests.support.rig_fixtures import STATION_FILE


def simulate_args(out: Path, *extra: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    simulate.add_arguments(parser)
    return parser.parse_args(["--config", str(STATION_FILE), "--out", str(out), *extra])


def test_writes_a_trace_that_stops_at_the_target(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run.csv"
    assert simulate.run(simulate_args(out, "--seed", "3")) == 0
    trace = read_trace(out)
    assert trace.has_force
    assert np.all(np.diff(trace.time_s) > 0)
    assert 56_000.0 <= np.max(trace.force_n) < 62_000.0
    printed = capsys.readouterr().out
    assert f"{len(trace)} samples written" in printed
    assert "shutoff_force" in printed


def test_no_shutoff_runs_past_the_target(tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    assert simulate.run(simulate_args(out, "--seed", "3", "--no-shutoff")) == 0
    assert np.max(read_trace(out).force_n) > 70_000.0


def test_unknown_program_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no program 9"):
        simulate.run(simulate_args(tmp_path / "run.csv", "--program", "9"))
