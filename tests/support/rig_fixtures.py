"""Shared builders for the rig tests: the embedded station, quiet rigs, short programs."""

from __future__ import annotations

from shared.config import LoadedStation, Program, RigSection, load_station
from shared.model import JointConstants
from tests.support.paths import STATION_FILE


def station() -> LoadedStation:
    return load_station(STATION_FILE)


def constants() -> JointConstants:
    return JointConstants.of(station().joint)


def paper_program(**changes: object) -> Program:
    """Program 1 of the embedded station (the paper's experiment), optionally changed."""
    return station().config.program(1).model_copy(update=changes)


def quiet_rig(**changes: object) -> RigSection:
    """A rig without sensor noise and without friction scatter."""
    values: dict[str, object] = {
        "mu_stick_scatter": 0.0,
        "torque_noise_nm": 0.0,
        "force_noise_n": 0.0,
        "angle_noise_deg": 0.0,
    }
    values.update(changes)
    return RigSection.model_validate(values)


def paper_rig() -> RigSection:
    """The [rig] section of the embedded station (noise and scatter on)."""
    return station().config.rig
