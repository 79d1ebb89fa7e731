"""Real controller runs imported as a person imports them, and their recordings read back."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import jsonschema
from mcap.reader import make_reader

from services.cli.main import main
from shared.offline.controller_import import read_controller_run


def messages_by_topic(path: Path) -> dict[str, list[dict[str, Any]]]:
    """Every message of the recording, decoded with ``json`` alone, by topic suffix."""
    out: dict[str, list[dict[str, Any]]] = defaultdict(list)
    validators: dict[int, jsonschema.Draft202012Validator] = {}
    with path.open("rb") as handle:
        for schema, channel, message in make_reader(handle).iter_messages():
            assert schema is not None and channel.message_encoding == "json", channel.topic
            if schema.id not in validators:
                validators[schema.id] = jsonschema.Draft202012Validator(json.loads(schema.data))
            data = json.loads(message.data)
            validators[schema.id].validate(data)
            out[channel.topic.rsplit("/", 1)[1]].append(data)
    return out


def import_runs(runs: list[Path], recordings: Path, *extra: str) -> int:
    return main(["import", *map(str, runs), "--recordings", str(recordings), "--no-rerun", *extra])


def recording_of(recordings: Path, source: Path) -> Path:
    run = read_controller_run(source)
    (path,) = recordings.glob(f"cs351/*/cs351_run{run.run_id}_*.mcap")
    return path
