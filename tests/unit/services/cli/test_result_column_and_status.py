"""``up`` prints each run's OK/NOK; ``status`` shows the last result and why."""

from __future__ import annotations

import json
from typing import Any

from services.cli import run_table
from services.cli.station_status_text import format_report
from shared.contract import JudgedFigure, TighteningResult, channels, encode, keys
from shared.line_status import StatusCollector, to_json
from tests.support import factories
from tests.support.factories import summary

T0 = 1_800_000_000_000_000_000
S = 1_000_000_000


def result(run_id: int = 3, **changes: Any) -> TighteningResult:
    """A NOK result: its preload low, its angle not judged."""
    nok: dict[str, Any] = {
        "program_name": "M14 to 56 kN",
        "time_ns": T0,
        "final_torque_nm": JudgedFigure(190.0, 150.0, 250.0, "ok"),
        "final_angle_deg": JudgedFigure(61.0, None, None, "not_judged"),
        "final_force_n": JudgedFigure(52800.0, 53000.0, 59000.0, "low"),
        "result": "NOK",
        "nok_reasons": "preload low: 52800 N, window 53000 to 59000 N",
        "stop_reason": "plateau_closest",
        "source": "predictor",
    }
    return factories.result(run_id, **{**nok, **changes})


def test_the_up_table_has_a_result_column_with_ok_nok_or_a_dash() -> None:
    header = run_table.header()
    titles = header.splitlines()[0].split()
    assert titles[titles.index("%") + 1] == "result"  # right after "error %"
    ok = run_table.row(summary(3), result=result(3, result="OK", nok_reasons=""))
    nok = run_table.row(summary(4), result=result(4))
    missing = run_table.row(summary(5))
    assert ok.split()[7] == "OK" and nok.split()[7] == "NOK" and missing.split()[7] == "-"
    # the fixed columns line up; the part, last, is as wide as its id
    fixed = len(header.splitlines()[0]) - len("part")
    assert {len(row) - len(row.split()[-1]) for row in (ok, nok, missing)} == {fixed}
    line = run_table.totals(
        [summary(3), summary(4), summary(5)], [result(3, result="OK"), result(4)]
    )
    assert line.endswith("1 OK, 1 NOK, 1 without a result")


def test_the_up_table_ends_with_the_part_each_result_names() -> None:
    header = run_table.header(station_column=True).splitlines()[0]
    assert header.split()[-1] == "part"
    on_part = run_table.row(summary(3), True, result(3, part_id="WVWZZZ1JZXW000001"))
    no_part = run_table.row(summary(4), True, result(4))
    missing = run_table.row(summary(5), True)
    assert on_part.split()[0] == "st1" and on_part.split()[-1] == "WVWZZZ1JZXW000001"
    assert no_part.split()[-1] == "-" and missing.split()[-1] == "-"
    assert on_part.index("WVWZZZ1JZXW000001") == header.index("part")
    results = [result(n, part_id=part) for n, part in ((3, "P1"), (4, "P1"), (5, "P2"), (6, None))]
    line = run_table.totals([summary(n) for n in (3, 4, 5, 6)], results)
    assert line.endswith("0 OK, 4 NOK, 2 parts")
    one = run_table.totals([summary(3)], [result(3, part_id="P1")])
    assert one.endswith(", 1 part")


def test_status_shows_the_last_result_its_verdict_why_and_figures() -> None:
    collector = StatusCollector()
    key = keys.station_key("st1", channels.RESULTS.topic)
    collector.message(key, encode(result(2, result="OK", nok_reasons="")), T0)
    collector.message(key, encode(result(3)), T0 + S)

    report = collector.report("e", 2.0, T0 + 3 * S)
    (status,) = report.stations
    assert status.last_result is not None
    assert (status.last_result.run_id, status.last_result.result) == (3, "NOK")
    assert status.last_result.age_s == 3.0
    text = format_report(report)
    assert (
        "last result   run 3: NOK (preload low: 52800 N, window 53000 to 59000 N), "
        "torque 190.0 Nm ok, angle 61.0 deg not judged, preload 52.80 kN low, "
        "from the predictor, 3.0 s ago"
    ) in text
    as_json = json.loads(json.dumps(to_json(report)))
    assert as_json["stations"]["st1"]["last_result"]["force_status"] == "low"


def test_status_without_a_result_says_none_and_a_bad_one_is_unreadable() -> None:
    collector = StatusCollector()
    collector.message(keys.station_key("st1", channels.RESULTS.topic), b'{"result": 1}', T0)
    (status,) = collector.report("e", 2.0, T0).stations
    assert status.last_result is None and status.unreadable_messages == 1
    assert "last result   - (none in the window)" in format_report(collector.report("e", 2, T0))
