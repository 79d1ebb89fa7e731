"""How a run is judged OK or NOK: each final figure against its window, then the verdict.

Pure and shared by every maker of a :class:`~shared.contract.messages.TighteningResult`
(the live predictor, ``boltwatch import``, a controller bridge), so a figure
is judged the same way wherever the run came from:

- :func:`judge`: a figure against its window. Below the minimum: ``low``;
  above the maximum: ``high``; within (bounds included): ``ok``; no window,
  or no value: ``not_judged``. A value that is not a finite number is no
  measurement: it becomes None (a result never carries NaN).
- :func:`figure_reasons`: what in the figures makes a run NOK: a figure out
  of its window, and a figure that has a window but no value (a run that
  cannot show it ended in its window is not OK).
- :func:`verdict`: NOK when there is any reason, else OK; :func:`reasons_text`:
  the reasons as the result carries them (``"; "``-separated).
"""

from __future__ import annotations

import math

from shared.contract import MAX_TEXT_CHARS, FigureStatus, JudgedFigure, Verdict

NOT_JUDGED: FigureStatus = "not_judged"


def judge(value: float | None, low: float | None, high: float | None) -> JudgedFigure:
    """``value`` (None or not finite: not measured) against the window [low, high]."""
    if value is not None and not math.isfinite(value):
        value = None
    if value is None or (low is None and high is None):
        return JudgedFigure(value, low, high, NOT_JUDGED)
    if low is not None and value < low:
        return JudgedFigure(value, low, high, "low")
    if high is not None and value > high:
        return JudgedFigure(value, low, high, "high")
    return JudgedFigure(value, low, high, "ok")


def figure_reasons(figures: dict[str, tuple[JudgedFigure, str]]) -> list[str]:
    """Why the figures make the run NOK; ``figures``: name -> (figure, unit)."""
    reasons = []
    for name, (figure, unit) in figures.items():
        if figure.min is None and figure.max is None:
            continue  # no window: never a reason
        window = _window_text(figure, unit)
        if figure.status == "low":
            reasons.append(f"{name} low: {figure.value:g} {unit}, {window}")
        elif figure.status == "high":
            reasons.append(f"{name} high: {figure.value:g} {unit}, {window}")
        elif figure.value is None:
            reasons.append(f"{name} not measured, {window}")
    return reasons


def verdict(reasons: list[str]) -> Verdict:
    return "NOK" if reasons else "OK"


def reasons_text(reasons: list[str]) -> str:
    """The reasons as one text (bounded like every text of a message)."""
    return cut_text("; ".join(reasons))


def cut_text(text: str) -> str:
    """``text`` within :data:`~shared.contract.message_fields.MAX_TEXT_CHARS` characters."""
    if len(text) <= MAX_TEXT_CHARS:
        return text
    return text[: MAX_TEXT_CHARS - 3] + "..."


def _window_text(figure: JudgedFigure, unit: str) -> str:
    if figure.min is not None and figure.max is not None:
        return f"window {figure.min:g} to {figure.max:g} {unit}"
    if figure.min is not None:
        return f"at least {figure.min:g} {unit}"
    return f"at most {figure.max:g} {unit}"
