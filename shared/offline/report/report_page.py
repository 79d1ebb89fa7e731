"""The report as one self-contained HTML file, and as the lines printed on the terminal.

The page holds, per program, a table of its figures (n, mean, σ, window, Cp,
Cpk, control-chart type and subgroups out of control), its NOK reasons and
stop reasons, then the report's picture embedded as a ``data:`` PNG: no
script, no style sheet, nothing fetched, so it opens from a share or a mail
on a machine without internet. A multi-spindle station's program is followed
by a table of its spindles side by side (runs, NOK, mean and Cpk of each
figure: the spindle that drifts stands out) and each spindle's own section.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence

from shared.quality import FigureStatistics, ProgramStatistics, window_text

_STYLE = (
    "body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;margin:.5em 0}"
    "td,th{border:1px solid #bbb;padding:.2em .6em;text-align:right}"
    "th{background:#eee}td.name{text-align:left}img{max-width:100%}"
)


def _number(value: float | None, digits: int = 6) -> str:
    return "–" if value is None else f"{value:.{digits}g}"


def _cp_cell(value: float | None, statistics: FigureStatistics) -> str:
    if value is not None:
        return f"{value:.2f}"
    return html.escape(f"not computed: {statistics.capability.not_computed or 'one-sided'}")


def _chart_cell(statistics: FigureStatistics) -> str:
    chart = statistics.chart
    if chart is None:
        return "less than one subgroup"
    left = f", {chart.left_out} runs left out" if chart.left_out else ""
    return (
        f"X̄/{chart.spread}, {len(chart.means)} × {chart.size}{left}; "
        f"{chart.out_of_control} out of control"
    )


def _program_section(program: ProgramStatistics) -> str:
    rows = []
    for figure in program.figures:
        cap = figure.capability
        rows.append(
            "<tr>"
            f"<td class=name>{html.escape(figure.title)}</td><td>{html.escape(figure.unit)}</td>"
            f"<td>{cap.n}</td><td>{_number(cap.mean)}</td><td>{_number(cap.sigma, 3)}</td>"
            f"<td>{html.escape(window_text(cap.lower, cap.upper))}</td>"
            f"<td>{_cp_cell(cap.cp, figure)}</td><td>{_cp_cell(cap.cpk, figure)}</td>"
            f"<td class=name>{html.escape(_chart_cell(figure))}</td></tr>"
        )
    reasons = (
        "".join(
            f"<tr><td class=name>{html.escape(name)}</td><td>{count}</td></tr>"
            for name, count in program.nok_reasons
        )
        or "<tr><td class=name>no NOK</td><td>0</td></tr>"
    )
    stops = "".join(
        f"<tr><td class=name>{html.escape(name)}</td><td>{count}</td></tr>"
        for name, count in program.stop_reasons
    )
    notes = "".join(f"<p>{html.escape(change)}</p>" for change in program.window_changes)
    if program.staged_runs:
        notes += f"<p>{html.escape(pulses_text(program))}</p>"
    title = f"Program {program.program_id}: {html.escape(program.program_name or 'unnamed')}"
    if program.spindle is not None:
        title += f", spindle {program.spindle}"
    return (
        f"<h2>{title}</h2>"
        f"<p>stations {html.escape(', '.join(program.stations))}; tools "
        f"{', '.join(map(str, program.tools))}; {program.runs} runs; NOK {program.noks} "
        f"({100 * program.nok_rate:.1f} %)</p>{notes}"
        "<table><tr><th>figure</th><th>unit</th><th>n</th><th>mean</th><th>σ</th>"
        "<th>window</th><th>Cp</th><th>Cpk</th><th>control chart</th></tr>"
        f"{''.join(rows)}</table>"
        f"<table><tr><th>NOK reason</th><th>runs</th></tr>{reasons}</table>"
        f"<table><tr><th>stop reason</th><th>runs</th></tr>{stops}</table>"
    )


def _spindles_table(spindles: Sequence[ProgramStatistics]) -> str:
    """A program's spindles side by side: runs, NOK, and each figure's mean and Cpk."""
    if not spindles:
        return ""
    heads = "".join(
        f"<th>{html.escape(figure.title)} mean</th><th>Cpk</th>" for figure in spindles[0].figures
    )
    rows = []
    for spindle in spindles:
        cells = "".join(
            f"<td>{_number(figure.capability.mean)}</td>"
            f"<td>{_cp_cell(figure.capability.cpk, figure)}</td>"
            for figure in spindle.figures
        )
        rows.append(
            f"<tr><td>{spindle.spindle}</td><td>{spindle.runs}</td><td>{spindle.noks}</td>{cells}</tr>"
        )
    first = spindles[0]
    return (
        f"<h2>Program {first.program_id}: its spindles side by side</h2>"
        f"<table><tr><th>spindle</th><th>runs</th><th>NOK</th>{heads}</tr>{''.join(rows)}</table>"
    )


def _sections(programs: Sequence[ProgramStatistics]) -> str:
    """Each program's section; a multi-spindle station's program, then its spindles side by
    side, then each spindle's section."""
    parts = []
    for program in programs:
        if program.spindle is None:
            spindles = [
                p for p in programs if p.program_id == program.program_id and p.spindle is not None
            ]
            parts.append(_program_section(program) + _spindles_table(spindles))
        else:
            parts.append(_program_section(program))
    return "".join(parts)


def html_page(
    programs: Sequence[ProgramStatistics],
    title: str,
    scope: Sequence[str],
    png: bytes,
    wear: str = "",
) -> str:
    """The whole page: ``scope`` lines (what was read), tables, the tools' wear (``wear``,
    its HTML: :mod:`.report_wear`), the picture inline."""
    picture = base64.b64encode(png).decode("ascii")
    lines = "".join(f"<li>{html.escape(line)}</li>" for line in scope)
    return (
        "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>"
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>"
        f"<h1>{html.escape(title)}</h1><ul>{lines}</ul>"
        f"{_sections(programs)}{wear}"
        f'<h2>Charts</h2><img alt="{html.escape(title)}" src="data:image/png;base64,{picture}">'
        "</body></html>\n"
    )


def terminal_lines(programs: Sequence[ProgramStatistics]) -> list[str]:
    """The summary printed on the terminal: per program its runs, NOK rate and figures."""
    lines = []
    for program in programs:
        lines.append(
            f"{program.name}: {program.runs} runs, NOK {program.noks} "
            f"({100 * program.nok_rate:.1f} %)"
        )
        for figure in program.figures:
            cap = figure.capability
            cpk = (
                f"Cp {_number(cap.cp, 3)} Cpk {cap.cpk:.2f}"
                if cap.cpk is not None
                else f"Cpk not computed ({cap.not_computed})"
            )
            lines.append(
                f"  {figure.title:<18} n {cap.n:>4}  mean {_number(cap.mean):>9}  "
                f"σ {_number(cap.sigma, 4):>7}  {window_text(cap.lower, cap.upper)}  {cpk}"
            )
        if program.nok_reasons:
            top = ", ".join(f"{name} ({count})" for name, count in program.nok_reasons[:3])
            lines.append(f"  NOK reasons: {top}")
        stops = ", ".join(f"{name} ({count})" for name, count in program.stop_reasons)
        lines.append(f"  stop reasons: {stops}")
        if program.staged_runs:
            lines.append(f"  final stage: {pulses_text(program)}")
    return lines


def pulses_text(program: ProgramStatistics) -> str:
    """How often a program's final stage needed a pulse back to the target (a slip during
    the halt, won back): a quality signal."""
    share = 100.0 * program.pulsed_runs / program.staged_runs
    return (
        f"{program.staged_runs} runs in a final stage, {program.pulsed_runs} needed a pulse "
        f"({share:.1f} %)"
    )
