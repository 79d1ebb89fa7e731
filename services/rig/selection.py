"""Which program and seed a rig session uses (shared by ``serve rig`` and ``simulate``)."""

from __future__ import annotations

import numpy as np

from shared.config import LoadedStation, Program
from shared.errors import ConfigError


def choose_program(station: LoadedStation, program_id: int | None) -> Program:
    """The program ``program_id`` (``--program``), or the station's first; an unknown id is a
    ConfigError naming the station file and the programs it has."""
    config = station.config
    if program_id is None:
        return config.programs[0]
    try:
        return config.program(program_id)
    except KeyError as err:
        known = ", ".join(str(program.id) for program in config.programs)
        raise ConfigError(
            f"{station.path}: no program {program_id} (--program; the file has {known})"
        ) from err


def choose_seed(cli_seed: int | None, config_seed: int | None) -> int:
    """--seed, else the station's [rig] seed, else fresh entropy; never negative."""
    if cli_seed is not None:
        seed = cli_seed
    elif config_seed is not None:
        seed = config_seed
    else:
        seed = int(np.random.default_rng().integers(0, 1 << 63))
    if seed < 0:
        raise ConfigError(f"the seed must not be negative (got {seed})")
    return seed
