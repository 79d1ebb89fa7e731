"""Event metrics (Figure 3) and the envelope check of ``boltwatch model --validate``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from services.cli.commands import model as command
from shared.model import event_metrics, share


def test_metrics_by_hand() -> None:
    metrics = event_metrics(
        onset_time_s=np.array([1.0, 1.1, 1.3]),
        onset_model_time_s=np.array([2.0, 2.1, 2.3]),
        peak_torque_nm=np.array([100.0, 110.0, 120.0]),
        trough_torque_nm=np.array([90.0, 95.0, 100.0]),
        plateau_forces_n=np.array([1000.0, 1500.0, 2100.0]),  # the last slip has no plateau yet
        motor_speed_rad_s=0.5,
    )
    np.testing.assert_allclose(metrics.frequency_hz, [10.0])  # only event 1 is complete
    np.testing.assert_allclose(metrics.force_step_n, [600.0])
    np.testing.assert_allclose(metrics.torque_drop_nm, [15.0])
    np.testing.assert_allclose(metrics.k1, [21.0])
    np.testing.assert_allclose(metrics.k2, [600.0 / 0.1 * 0.5])
    np.testing.assert_allclose(metrics.k3, [15.0 / 2.1 * 0.5])


def test_share_counts_both_sides() -> None:
    counted = share(np.array([0.5, 1.0, 1.5, 3.0]), np.array([1.0] * 4), 2.0)
    assert (counted.below, counted.inside, counted.above, counted.count) == (1, 2, 1, 4)


def test_validate_keeps_the_rig_inside_frequency_and_force_envelopes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    out = tmp_path / "validate.png"
    assert command.run(parser.parse_args(["--validate", "--json", "--out", str(out)])) == 0
    rows = json.loads(capsys.readouterr().out)
    assert len(rows) == len(command.VALIDATION_GRID)
    for row in rows:
        assert row["events"] >= 5
        for key in ("frequency", "force_step", "k1", "k2"):
            assert row["shares"][key]["inside"] == row["events"], (row["joint"], key)
    assert out.read_bytes()[:4] == b"\x89PNG"
