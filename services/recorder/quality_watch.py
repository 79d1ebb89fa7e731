"""The quality alert: a program's rolling Cpk or its NOKs out of bounds, put on zenoh.

Fed every :class:`~shared.contract.messages.TighteningResult` the recorder receives;
per (station, program) it keeps the last results and checks, with the
station file's ``[quality]`` section (:mod:`shared.config.quality`):

- ``cpk_low``: the Cpk (:mod:`.capability`, numpy) of each figure (torque,
  angle, preload) over the last ``window_runs`` results with that figure,
  against the newest result's window, below ``cpk_min``; not computed before
  ``min_runs`` such results (nor without a window, nor with σ = 0);
- ``nok_run``: the newest ``nok_run`` results all NOK;
- ``nok_rate``: ``nok_max`` or more NOKs among the last ``nok_window`` results.

A :class:`~shared.contract.messages.QualityAlert` is put when a condition starts
(``active``), not at every result while it lasts; once when it clears
(``active`` False), and again if it returns. A result heard twice (same run,
same end) counts once.
"""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from shared.config import QualitySection
from shared.contract import (
    JudgedFigure,
    QualityAlert,
    QualityAlertKind,
    QualityFigure,
    TighteningResult,
)
from shared.quality import capability, window_text

LOG = logging.getLogger(__name__)

#: the figures whose Cpk is watched, with how a result carries them
FIGURES: tuple[tuple[QualityFigure, Callable[[TighteningResult], JudgedFigure]], ...] = (
    ("torque", lambda result: result.final_torque_nm),
    ("angle", lambda result: result.final_angle_deg),
    ("preload", lambda result: result.final_force_n),
)

#: a condition: (kind, figure) -> its alert while active
_Key = tuple[QualityAlertKind, QualityFigure | None]


@dataclass
class _Program:
    """The last results of one program at one station and the conditions active now."""

    results: deque[TighteningResult]
    active: set[_Key] = field(default_factory=set)


class QualityWatch:
    """Check each result's program; call ``alert`` when a condition starts or clears."""

    def __init__(
        self, settings: Mapping[str, QualitySection], alert: Callable[[QualityAlert], None]
    ) -> None:
        self._settings = dict(settings)  # by station
        self._alert = alert
        self._programs: dict[tuple[str, int], _Program] = {}
        #: the alert that started each condition active now, by (station, program, condition)
        self._active: dict[tuple[str, int, _Key], QualityAlert] = {}
        self.alerts = 0  # alerts put (starting and clearing)

    def active(self, station: str) -> list[QualityAlert]:
        """The alerts of ``station`` active now, newest first (RecorderStats carries them)."""
        alerts = [alert for (st, _, _), alert in self._active.items() if st == station]
        return sorted(alerts, key=lambda alert: alert.time_ns, reverse=True)

    def on_result(self, result: TighteningResult) -> list[QualityAlert]:
        """Take one result; the alerts it starts or clears (each given to ``alert`` too)."""
        settings = self._settings.get(result.station)
        if settings is None:
            return []
        key = (result.station, result.program_id)
        program = self._programs.get(key)
        if program is None:
            kept = max(settings.window_runs, settings.nok_window, settings.nok_run)
            program = self._programs[key] = _Program(deque(maxlen=kept))
        if any(_same_run(result, seen) for seen in program.results):
            return []
        program.results.append(result)
        found = [
            *_cpk_checks(program.results, settings, result),
            *_nok_checks(program.results, settings, result),
        ]
        alerts = []
        for alert in found:
            condition = (alert.kind, alert.figure)
            if alert.active == (condition in program.active):
                continue  # still active, or still clear: nothing new to say
            if alert.active:
                program.active.add(condition)
                self._active[(*key, condition)] = alert
                LOG.warning("quality alert at %s: %s", result.station, alert.text)
            else:
                program.active.discard(condition)
                self._active.pop((*key, condition), None)
                LOG.info("quality alert at %s cleared: %s", result.station, alert.text)
            alerts.append(alert)
            self.alerts += 1
            self._alert(alert)
        return alerts


def _same_run(one: TighteningResult, other: TighteningResult) -> bool:
    return (one.run_id, one.tightening_id, one.time_ns) == (
        other.run_id,
        other.tightening_id,
        other.time_ns,
    )


def _cpk_checks(
    results: deque[TighteningResult], settings: QualitySection, newest: TighteningResult
) -> list[QualityAlert]:
    """A cpk_low alert per figure whose Cpk is computed: active when below ``cpk_min``."""
    alerts = []
    window = list(results)[-settings.window_runs :]
    for name, figure_of in FIGURES:
        values = [
            value
            for value in (figure_of(result).value for result in window)
            if value is not None and math.isfinite(value)
        ]
        if len(values) < settings.min_runs:
            continue
        judged = figure_of(newest)
        figure = capability(values, judged.min, judged.max)
        if figure.cpk is None:
            continue
        low = figure.cpk < settings.cpk_min
        words = "below" if low else "back to at least"
        text = (
            f"program {newest.program_id}: {name} Cpk {figure.cpk:.3g} {words} "
            f"{settings.cpk_min:g} over the last {figure.n} runs "
            f"({window_text(judged.min, judged.max)})"
        )
        alerts.append(
            _alert(newest, "cpk_low", name, figure.cpk, settings.cpk_min, figure.n, low, text)
        )
    return alerts


def _nok_checks(
    results: deque[TighteningResult], settings: QualitySection, newest: TighteningResult
) -> list[QualityAlert]:
    """The nok_run and nok_rate conditions after the newest result."""
    in_a_row = 0
    for result in reversed(results):
        if result.result != "NOK":
            break
        in_a_row += 1
    streak = in_a_row >= settings.nok_run
    program = f"program {newest.program_id}"
    last = list(results)[-settings.nok_window :]
    noks = sum(result.result == "NOK" for result in last)
    rate = noks >= settings.nok_max
    return [
        _alert(
            newest,
            "nok_run",
            None,
            in_a_row,
            settings.nok_run,
            in_a_row,
            streak,
            f"{program}: {in_a_row} NOK in a row (alert at {settings.nok_run})",
        ),
        _alert(
            newest,
            "nok_rate",
            None,
            noks,
            settings.nok_max,
            len(last),
            rate,
            f"{program}: {noks} NOK of the last {len(last)} runs (alert at {settings.nok_max} "
            f"of {settings.nok_window})",
        ),
    ]


def _alert(
    result: TighteningResult,
    kind: QualityAlertKind,
    figure: QualityFigure | None,
    value: float,
    limit: float,
    runs: int,
    active: bool,
    text: str,
) -> QualityAlert:
    return QualityAlert(
        station=result.station,
        program_id=result.program_id,
        time_ns=result.time_ns,
        kind=kind,
        figure=figure,
        value=float(value),
        limit=float(limit),
        runs=runs,
        active=active,
        text=text,
    )
