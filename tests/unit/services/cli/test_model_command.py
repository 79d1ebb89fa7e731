"""``boltwatch model``: the report, JSON, plot and one-line errors."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from services.cli.commands import model as command
from shared.errors import BoltwatchError, ConfigError, InputError
from tests.support.paths import JOINTS


def run(*argv: str) -> int:
    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    return command.run(
        parser.parse_args(["--joint", str(JOINTS / "paper-section-5-2.toml"), *argv])
    )


def test_json_report_of_section_5_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert run("--json") == 0
    report = json.loads(capsys.readouterr().out)
    assert round(report["torque_preload"]["mu_total"], 2) == 0.18
    assert round(report["torque_preload"]["mu_apparent"], 2) == 0.32
    at = report["at_target"]
    assert at["stick_slip_frequency_min_hz"] < at["stick_slip_frequency_max_hz"]
    assert report["resonance"]["near_stick_slip_band"] is False
    assert report["time"]["basis"] == "target force"


def test_text_report_names_the_sections(capsys: pytest.CaptureFixture[str]) -> None:
    assert run("--target-torque", "150") == 0
    out = capsys.readouterr().out
    assert "γ_stick" in out and "stick-slip frequency" in out and "K2" in out
    assert "target torque reached" in out and "target force" not in out


def test_eq_30_when_thread_and_bearing_friction_given(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = (JOINTS / "paper-section-5-2.toml").read_text(encoding="utf-8")
    joint = tmp_path / "joint.toml"
    joint.write_text(text + "mu_thread = 0.18\nmu_bearing = 0.18\n", encoding="utf-8")
    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    args = parser.parse_args(["--joint", str(joint), "--target-force", "56000", "--json"])
    assert command.run(args) == 0
    section = json.loads(capsys.readouterr().out)["torque_preload"]
    # eq. 30 with μ_th = μ_b = μ_total gives back about the paper's 200 Nm
    assert section["torque_for_target_force_nm"] == pytest.approx(199.2, abs=0.5)
    assert "mu_total" not in section


def test_plot_is_written(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "model.png"
    assert run("--plot", str(out)) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert str(out) in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "error", "match"),
    [
        (("--plot", "out.svg"), InputError, "PNG"),
        (("--joint", "no/such/joint.toml"), ConfigError, "file not found"),
    ],
)
def test_bad_input_is_one_clear_line(
    argv: tuple[str, ...], error: type[BoltwatchError], match: str
) -> None:
    with pytest.raises(error, match=match) as info:
        run(*argv)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "argv",
    [("--speed", "-1"), ("--speed", "1e308"), ("--target-force", "0"), ("--target-torque", "inf")],
)
def test_impossible_numbers_are_refused_while_parsing(
    argv: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    """1e308 rad/s and an infinite torque target were a ZeroDivisionError in the report."""
    with pytest.raises(SystemExit) as info:
        run(*argv)
    assert info.value.code == 2
    assert f"argument {argv[0]}: expected a number" in capsys.readouterr().err
