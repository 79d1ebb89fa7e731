"""The plant's wear: several lines' recorders' replies merged (recorder/wear_plant.py)."""

from __future__ import annotations

import json

import pytest

from shared.errors import InputError
from shared.wear import RunWear, ToolWear, WearReply, merge, parse_reply

T0_NS = 1_700_000_000_000_000_000


def tool(tool_id: int, runs: list[tuple[str, float]], service_ns: int | None = None) -> ToolWear:
    """A ledger's line for ``tool_id`` with ``runs`` (station, I_process), all since service."""
    total = sum(intensity for _, intensity in runs)
    worst = sorted(
        (RunWear(st, i, intensity, T0_NS + i) for i, (st, intensity) in enumerate(runs)),
        key=lambda run: -run.process_intensity,
    )[:3]
    return ToolWear(
        tool_id, len(runs), total, total / len(runs), service_ns, "socket" if service_ns else None,
        len(runs), total, worst, sorted({st for st, _ in runs}),
    )  # fmt: skip


def test_a_tool_on_two_lines_adds_up_and_a_line_with_two_stations_counts_once() -> None:
    line1 = tool(7, [("st1", 1.0), ("st2", 4.0)])  # line 1: st1 and st2, one ledger
    line2 = tool(7, [("st3", 2.0)], service_ns=T0_NS - 1)
    replies = [
        WearReply("st1", "a:/line1/wear.sqlite", [line1, tool(8, [("st1", 5.0)])]),
        WearReply("st2", "a:/line1/wear.sqlite", [line1]),  # same ledger, same line
        WearReply("st3", "b:/line2/wear.sqlite", [line2]),
    ]
    seven, eight = merge(replies)
    assert (seven.tool_id, seven.runs, seven.total_intensity) == (7, 3, 7.0)
    assert seven.intensity_per_run == pytest.approx(7.0 / 3)
    assert seven.stations == ["st1", "st2", "st3"]
    assert [run.process_intensity for run in seven.worst_runs] == [4.0, 2.0, 1.0]
    assert (seven.last_service_ns, seven.last_service_note) == (T0_NS - 1, "socket")
    assert (seven.runs_since_service, seven.intensity_since_service) == (3, 7.0)
    assert (eight.runs, eight.total_intensity) == (1, 5.0)
    assert [t.tool_id for t in merge(replies, station="st3")] == [7]  # whole totals
    assert merge(replies, station="st3")[0].runs == 3


def test_a_reply_taken_while_a_run_was_added_counts_the_later_line() -> None:
    before = tool(7, [("st1", 1.0)])
    after = tool(7, [("st1", 1.0), ("st2", 2.0)])
    replies = [WearReply("st1", "a:/l", [before]), WearReply("st2", "a:/l", [after])]
    (merged,) = merge(replies)
    assert merged.runs == 2 and merged.total_intensity == 3.0


def test_a_recorders_reply_parses_and_a_broken_one_is_an_input_error() -> None:
    line = tool(7, [("st1", 1.0)])
    body = {
        "station": "st1",
        "ledger": "/r/wear.sqlite",
        "host": "line1",
        "tools": [line.to_dict()],
    }
    reply = parse_reply(json.dumps(body).encode())
    assert reply == WearReply("st1", "line1:/r/wear.sqlite", [line])
    with pytest.raises(InputError, match="not a wear reply"):
        parse_reply(b'{"station": "st1"}')
    with pytest.raises(InputError, match="not a wear reply"):
        parse_reply(b"\xff")
