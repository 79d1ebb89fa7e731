"""A single-spindle station's messages and files read, and write, as before stations had
spindles: the recording in ``tests/data/single-spindle`` (written by the code before) decodes
with today's types, each message encodes back to the very bytes recorded, and a multi-spindle
station's messages carry their spindle and sync id."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from shared.contract import (
    SCHEMA_TYPES,
    CycleResult,
    CycleSpindle,
    RunSummary,
    TighteningResult,
    ToolState,
    decode,
    encode,
    to_dict,
)
from shared.errors import InputError
from tests.support.paths import REPO

SINGLE_SPINDLE = REPO / "tests" / "data" / "single-spindle"
RECORDING = SINGLE_SPINDLE / "st1_run1795880314_153835.mcap"


def recorded(path: Path) -> list[tuple[str, bytes]]:
    """(schema name, payload) of every typed message of a recording, in file order."""
    with path.open("rb") as handle:
        return [
            (schema.name, message.data)
            for schema, _channel, message in make_reader(handle).iter_messages()
            if schema is not None and schema.name in SCHEMA_TYPES
        ]


def test_a_recording_made_before_spindles_decodes_and_encodes_to_the_same_bytes() -> None:
    messages = recorded(RECORDING)
    kinds = {name for name, _ in messages}
    # the run's states, summary and result are among them: the messages that grew
    assert {"boltwatch.ToolState", "boltwatch.RunSummary", "boltwatch.TighteningResult"} <= kinds
    for name, payload in messages:
        message: Any = decode(SCHEMA_TYPES[name], payload)
        assert encode(message) == payload, name
        if hasattr(message, "spindle"):
            assert message.spindle is None and message.sync_id is None


def test_a_single_spindle_station_writes_no_spindle_field() -> None:
    state = ToolState("st1", 1795880314, 7, 1, "running", 1_795_880_314_000_000_000)
    assert b"spindle" not in encode(state) and b"sync_id" not in encode(state)
    assert "spindle" not in to_dict(state)


def test_a_spindles_run_carries_its_spindle_and_sync_id_through_the_codec() -> None:
    state = ToolState("st1", 11, 8, 1, "running", 5, spindle=2, sync_id=10)
    assert decode(ToolState, encode(state)) == state
    assert to_dict(state)["spindle"] == 2 and to_dict(state)["sync_id"] == 10
    for message_type in (RunSummary, TighteningResult):
        hints = message_type.__dataclass_fields__
        assert hints["spindle"].default is None and hints["sync_id"].default is None


@pytest.mark.parametrize("spindle", [0, 100, -1])
def test_a_spindle_number_outside_1_to_99_is_refused_naming_the_field(spindle: int) -> None:
    payload = encode(ToolState("st1", 11, 8, 1, "running", 5)).replace(
        b"}", f',"spindle":{spindle}}}'.encode()
    )
    with pytest.raises(InputError, match="spindle"):
        decode(ToolState, payload)


def test_a_cycle_result_names_its_spindles_runs_in_spindle_order() -> None:
    cycle = CycleResult(
        station="st1",
        sync_id=10,
        time_ns=5,
        part_id="st1-P000010",
        program_id=1,
        result="NOK",
        nok_reasons="spindle 2 no result",
        source="predictor",
        spindles=[
            CycleSpindle(1, 10, "OK"),
            CycleSpindle(2, None, None),
            CycleSpindle(3, 12, "OK"),
        ],
    )
    assert decode(CycleResult, encode(cycle)) == cycle
    assert cycle.run_ids == [10, 12]


def test_the_wear_ledger_a_single_spindle_station_wrote_before_reads_as_it_did(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``tests/data/single-spindle/wear.sqlite`` answers ``wear --json`` as it did then (every
    key it gave then, with the same values; a tool's forecast, ``outlook``, came later)."""
    import json
    import shutil

    from services.cli.main import main

    folder = tmp_path / "recordings"
    folder.mkdir()
    shutil.copy(SINGLE_SPINDLE / "wear.sqlite", folder / "wear.sqlite")
    capsys.readouterr()
    assert main(["wear", "--recordings", str(folder), "--json"]) == 0
    answered = json.loads(capsys.readouterr().out)
    then = json.loads((SINGLE_SPINDLE / "wear.json").read_text())
    assert [
        {key: tool[key] for key in old} for tool, old in zip(answered, then, strict=True)
    ] == then
