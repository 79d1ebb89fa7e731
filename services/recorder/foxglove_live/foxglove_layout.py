"""The Foxglove layout of one station: what the engineer at the station looks at.

Four panels on the station's channels (the same topics live and in the MCAP
files, so the layout serves both): torque and preload over time (samples),
torque over angle (samples), an OK/NOK indicator (results: ``result``), and
the decision log (every stop decision's reason on the time line, the newest
decision in full). Each panel's configuration is built with the foxglove-sdk's
typed panel configs (:mod:`foxglove.layouts`); they are put in the layout
file format a Foxglove app exports and imports (Layouts, Import from file):
``configById`` and a ``layout`` tree of splits.

A topic named like ours (no leading ``/``) is quoted in a message path:
``"boltwatch/st1/samples".torque_nm``.

``python -m services.recorder.foxglove_live.foxglove_layout [--station ID] [--out FILE]``
writes it; ``config/foxglove/boltwatch-layout.json`` is its output for ``st1``
(a test checks they agree).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import foxglove.layouts as fl

from shared.contract import channels

DEFAULT_STATION = "st1"
SHIPPED_LAYOUT = Path(__file__).resolve().parents[3] / "config/foxglove/boltwatch-layout.json"
OK_GREEN = "#2e9d3a"
NOK_RED = "#d12f2f"
WAITING_GREY = "#8c8c8c"


def field_path(topic: str, field: str) -> str:
    """A message path of one field: the topic quoted (it has no leading ``/``)."""
    return f'"{topic}".{field}'


def _config(model: Any) -> dict[str, Any]:
    """The camelCase JSON of one of the SDK's panel configs (unset keys left out)."""
    return dict(json.loads(model.to_json()))


def panels(station: str) -> dict[str, dict[str, Any]]:
    """The configuration of each panel, by panel id (``Type!name``)."""
    samples = channels.SAMPLES.key(station)
    results = channels.RESULTS.key(station)
    decisions = channels.DECISION.key(station)
    return {
        "Plot!torque_preload": _config(
            fl.PlotConfig(
                paths=[
                    fl.PlotSeries(
                        value=field_path(samples, "torque_nm"),
                        label="torque (Nm)",
                        enabled=True,
                        timestamp_method="receiveTime",
                    ),
                    fl.PlotSeries(
                        value=field_path(samples, "force_n"),
                        label="preload (N)",
                        enabled=True,
                        timestamp_method="receiveTime",
                        y_axis_id="preload",
                    ),
                ],
                secondary_axes=[fl.PlotSecondaryAxis(id="preload", label="preload (N)")],
                x_axis_val="timestamp",
                y_axis_label="torque (Nm)",
                show_legend=True,
                time_window_mode="sliding",
                following_view_width=10,
            )
        )
        | {"foxglovePanelTitle": f"{station}: torque and preload over time"},
        "Plot!torque_angle": _config(
            fl.PlotConfig(
                paths=[
                    fl.PlotSeries(
                        value=field_path(samples, "torque_nm"),
                        x_value_path=field_path(samples, "angle_deg"),
                        label="torque (Nm) over angle (deg)",
                        enabled=True,
                    )
                ],
                x_axis_val="custom",
                x_axis_path=fl.PlotXAxisPath(value=field_path(samples, "angle_deg"), enabled=True),
                x_axis_label="angle (deg)",
                y_axis_label="torque (Nm)",
                time_range="all",
            )
        )
        | {"foxglovePanelTitle": f"{station}: torque over angle"},
        "Indicator!result": _config(
            fl.IndicatorConfig(
                path=field_path(results, "result"),
                style="background",
                rules=[
                    fl.IndicatorRule(operator="=", raw_value="OK", color=OK_GREEN, label="OK"),
                    fl.IndicatorRule(operator="=", raw_value="NOK", color=NOK_RED, label="NOK"),
                ],
                fallback_color=WAITING_GREY,
                fallback_label="no result yet",
            )
        )
        | {"foxglovePanelTitle": f"{station}: last result"},
        "StateTransitions!decisions": _config(
            fl.StateTransitionsConfig(
                paths=[
                    fl.StateTransitionsSeries(
                        value=field_path(decisions, "reason"),
                        label="stop decision",
                        enabled=True,
                        timestamp_method="receiveTime",
                    )
                ],
                show_points=True,
            )
        )
        | {"foxglovePanelTitle": f"{station}: stop decisions"},
        "RawMessages!last_decision": _config(
            fl.RawMessagesConfig(topic_path=f'"{decisions}"', expansion="all")
        )
        | {"foxglovePanelTitle": f"{station}: last decision"},
    }


def layout(station: str = DEFAULT_STATION) -> dict[str, Any]:
    """The layout file's content: plots on the left, verdict and decisions on the right."""
    return {
        "configById": panels(station),
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": {
            "direction": "row",
            "first": {
                "direction": "column",
                "first": "Plot!torque_preload",
                "second": "Plot!torque_angle",
                "splitPercentage": 50,
            },
            "second": {
                "direction": "column",
                "first": "Indicator!result",
                "second": {
                    "direction": "column",
                    "first": "StateTransitions!decisions",
                    "second": "RawMessages!last_decision",
                    "splitPercentage": 40,
                },
                "splitPercentage": 25,
            },
            "splitPercentage": 65,
        },
    }


def layout_text(station: str = DEFAULT_STATION) -> str:
    return json.dumps(layout(station), indent=2) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="write the Foxglove layout of a station")
    parser.add_argument("--station", default=DEFAULT_STATION, help="station id (default st1)")
    parser.add_argument("--out", type=Path, default=SHIPPED_LAYOUT, help="the layout file")
    args = parser.parse_args(argv)
    args.out.write_text(layout_text(args.station))
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
