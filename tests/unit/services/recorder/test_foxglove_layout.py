"""The shipped Foxglove layout: what the generator writes, on topics and fields that exist."""

from __future__ import annotations

import json
import re
from typing import Any

from services.recorder.foxglove_live.foxglove_layout import SHIPPED_LAYOUT, layout, layout_text
from services.recorder.foxglove_live.foxglove_server import served_channels
from shared.contract import json_schema

PATH = re.compile(r'^"(?P<topic>[^"]+)"(?:\.(?P<field>\w+))?$')


def paths_of(node: Any) -> list[str]:
    """Every message path of a panel configuration."""
    found: list[str] = []
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("value", "path", "topicPath", "xValuePath") and isinstance(value, str):
                found.append(value)
            else:
                found.extend(paths_of(value))
    elif isinstance(node, list):
        for item in node:
            found.extend(paths_of(item))
    return found


def leaves(node: Any) -> list[str]:
    if isinstance(node, str):
        return [node]
    return leaves(node["first"]) + leaves(node["second"])


def test_the_shipped_layout_is_what_the_generator_writes() -> None:
    assert SHIPPED_LAYOUT.read_text() == layout_text("st1")


def test_every_path_names_a_served_topic_and_a_field_of_its_schema() -> None:
    schemas = {
        channel.key("st1"): json_schema(channel.message_type) for channel in served_channels()
    }
    content = json.loads(SHIPPED_LAYOUT.read_text())
    paths = paths_of(content["configById"])
    assert len(paths) >= 6
    for path in paths:
        match = PATH.match(path)
        assert match, path
        assert match["topic"] in schemas, path
        if match["field"]:
            assert match["field"] in schemas[match["topic"]]["properties"], path


def test_each_panel_is_placed_once_and_the_verdicts_are_the_results() -> None:
    content = layout("st2")
    assert sorted(leaves(content["layout"])) == sorted(content["configById"])
    indicator = content["configById"]["Indicator!result"]
    assert indicator["path"] == '"boltwatch/st2/results".result'
    result_schema = json_schema(
        next(c for c in served_channels() if c.topic == "results").message_type
    )
    rules = {rule["rawValue"] for rule in indicator["rules"]}
    assert rules == set(result_schema["properties"]["result"]["enum"]) == {"OK", "NOK"}
