"""The last tightening result ``boltwatch status`` heard of a station: its verdict and why.

From the latest :class:`~shared.contract.messages.TighteningResult` on
``boltwatch/<st>/results`` in the listening window (the live predictor's,
or a controller's): the run, OK or NOK with its reasons, each final figure
with its status, where it came from and how long ago the run ended.
Collected by :mod:`shared.line_status.station_status`, printed by
:mod:`services.cli.station_status_text`.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import TighteningResult

_NS = 1_000_000_000


@dataclass(frozen=True)
class LastResult:
    run_id: int
    result: str  # "OK" or "NOK"
    nok_reasons: str  # "" when OK
    torque_nm: float | None
    torque_status: str  # low | ok | high | not_judged
    angle_deg: float | None
    angle_status: str
    force_n: float | None
    force_status: str
    source: str  # predictor | controller | import
    age_s: float  # since the run ended


def last_result(result: TighteningResult | None, now_ns: int) -> LastResult | None:
    if result is None:
        return None
    return LastResult(
        run_id=result.run_id,
        result=result.result,
        nok_reasons=result.nok_reasons,
        torque_nm=result.final_torque_nm.value,
        torque_status=result.final_torque_nm.status,
        angle_deg=result.final_angle_deg.value,
        angle_status=result.final_angle_deg.status,
        force_n=result.final_force_n.value,
        force_status=result.final_force_n.status,
        source=result.source,
        age_s=round((now_ns - result.time_ns) / _NS, 3),
    )


def result_text(result: LastResult | None) -> str:
    """One line for a person: ``run 12: NOK (preload low: ...), torque 201.5 Nm ok, ...``."""
    if result is None:
        return "- (none in the window)"
    verdict = result.result
    if result.nok_reasons:
        verdict += f" ({result.nok_reasons})"
    figures = ", ".join(
        f"{name} {amount_text(value, unit)} {status.replace('_', ' ')}"
        for name, value, unit, status in (
            ("torque", result.torque_nm, "Nm", result.torque_status),
            ("angle", result.angle_deg, "deg", result.angle_status),
            ("preload", result.force_n, "N", result.force_status),
        )
        if value is not None or status != "not_judged"
    )
    figures = f", {figures}" if figures else ""
    return (
        f"run {result.run_id}: {verdict}{figures}, from the {result.source}, "
        f"{result.age_s:.1f} s ago"
    )


def amount_text(value: float | None, unit: str) -> str:
    """A figure in ``unit`` for a person: ``-`` when None, newtons as kN."""
    if value is None:
        return "-"
    if unit == "N":
        return f"{value / 1000:.2f} kN"
    return f"{value:.1f} {unit}"
