"""The parts of the simulated line: how many bolts each has, and the id the line scans.

The rig (``boltwatch serve rig``) stands in for the line's PLC too: before
the first run of each part it puts the part's id on ``boltwatch/<st>/part``
(:class:`~shared.contract.PartScan`), so that every result names its part.
``[rig] bolts_per_part`` runs tighten one part (a wheel, a cylinder head);
``[rig] part_pattern`` makes its id, a Python format text naming
``{station}`` and ``{first_run_id}`` (the run id of the part's first bolt:
run ids count the tool's tightenings, so no two parts of a station share
one, across restarts too). Filled with the widest values (a 64-character
station id, a 32-bit run id) it must give a valid part id
(:data:`~shared.contract.PART_ID`: printable ASCII, no space at either end,
at most :data:`~shared.contract.PART_ID_CHARS` characters).
"""

from __future__ import annotations

import string

from shared.contract import PART_ID, PART_ID_CHARS

#: the default: ``st1-P1718000000``, or ``st1-P001000`` for a first run id of 1000
DEFAULT_PART_PATTERN = "{station}-P{first_run_id:06d}"
#: the widest value of each name a part pattern may use
PART_PATTERN_WIDEST: dict[str, str | int] = {"station": "x" * 64, "first_run_id": 2**32 - 1}


def check_part_pattern(pattern: str) -> str:
    """``pattern`` when every id it makes is a valid part id; ValueError saying why not."""
    try:
        parsed = list(string.Formatter().parse(pattern))
    except ValueError as err:
        raise ValueError(f"not a format text: {err}") from err
    names = {name for _, name, _, _ in parsed if name is not None}
    unknown = names - set(PART_PATTERN_WIDEST)
    if unknown:
        raise ValueError(
            f"names {', '.join(repr(n) for n in sorted(unknown))}; expected only "
            f"{', '.join(PART_PATTERN_WIDEST)}"
        )
    for first_run_id in (0, PART_PATTERN_WIDEST["first_run_id"]):
        try:
            text = pattern.format(**{**PART_PATTERN_WIDEST, "first_run_id": first_run_id})
        except (KeyError, IndexError, ValueError) as err:
            raise ValueError(f"cannot be filled in: {err}") from err
        if len(text) > PART_ID_CHARS:
            raise ValueError(
                f"gives {len(text)} characters at its widest; a part id has at most {PART_ID_CHARS}"
            )
        if PART_ID.fullmatch(text) is None:
            raise ValueError(
                f"gives {text!r}: a part id is printable ASCII, no space at either end"
            )
    return pattern


def part_id(pattern: str, station: str, first_run_id: int) -> str:
    """The id of the part whose first bolt is run ``first_run_id`` at ``station``."""
    return pattern.format(station=station, first_run_id=first_run_id)
