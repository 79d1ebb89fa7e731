"""``boltwatch report``'s work: statistics per program of the results read, HTML and PNG
written.

Writes ``<out>/report.html`` (self-contained) and ``<out>/report.png`` (the
same charts). No result in the range is an :class:`InputError` (one line,
exit status 2), naming what was searched. The files skipped and the payloads
and results refused while reading are counted on the page (:func:`read_counts`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from shared.errors import InputError
from shared.offline.report.recorded_results import RecordedResults, ResultFilter
from shared.offline.report.report_figure import build_figure, png_bytes
from shared.offline.report.report_page import html_page
from shared.offline.report.report_wear import WearPart, wear_html
from shared.quality import ProgramStatistics, statistics_of

HTML_NAME = "report.html"
PNG_NAME = "report.png"


@dataclass(frozen=True, slots=True)
class WrittenReport:
    """What was written and from what."""

    html_path: Path
    png_path: Path
    programs: list[ProgramStatistics]
    files: int
    results: int
    damaged: list[str]
    skipped: list[str]  # files not read at all, one line each
    refused: list[str]  # payloads and results refused, one line each


def describe_scope(rule: ResultFilter, subgroup_size: int) -> list[str]:
    """What the report covers, in words (the page's first lines, the error's text)."""
    stations = ", ".join(f"{station} ({folder})" for station, folder in rule.stations)
    since = rule.since.isoformat() if rule.since else "the first recording"
    until = rule.until.isoformat() if rule.until else "now"
    lines = [f"stations: {stations}", f"results that ended from {since} until {until} (UTC)"]
    if rule.program_id is not None:
        lines.append(f"program {rule.program_id} only")
    if rule.tool_id is not None:
        lines.append(f"tool {rule.tool_id} only")
    lines.append(
        f"control charts: consecutive subgroups of {subgroup_size} runs "
        f"({'X̄/R' if subgroup_size <= 10 else 'X̄/s'}); σ, Cp, Cpk over every run (ddof=1)"
    )
    return lines


def read_counts(read: RecordedResults) -> str:
    """What was left out while reading, in words ("" when nothing was)."""
    parts = []
    if read.damaged:
        parts.append(f"damaged files read as far as they go: {len(read.damaged)}")
    if read.skipped:
        parts.append(f"files not readable, skipped: {len(read.skipped)}")
    if read.refused:
        parts.append(f"results and payloads refused: {len(read.refused)}")
    return "; ".join(parts)


def write_report(
    rule: ResultFilter,
    read: RecordedResults,
    out: Path,
    subgroup_size: int,
    source: str,
    wear: WearPart | None = None,
) -> WrittenReport:
    """Compute, draw and write what was read (``source``: from where, in words; ``wear``:
    the tools' wear and forecasts, None: no ledger); InputError when no result is in range."""
    left_out = read_counts(read)
    if not read.results:
        searched = "; ".join(describe_scope(rule, subgroup_size)[:-1])
        left = f"; {left_out}" if left_out else ""
        raise InputError(f"no tightening results in range ({searched}; {source}{left})")
    programs = [statistics_of(columns, subgroup_size) for columns in read.programs]
    title = f"boltwatch report: {', '.join(station for station, _ in rule.stations)}"
    figure = build_figure(programs, title)
    png = png_bytes(figure)
    out.mkdir(parents=True, exist_ok=True)
    png_path, html_path = out / PNG_NAME, out / HTML_NAME
    png_path.write_bytes(png)
    scope = [*describe_scope(rule, subgroup_size), f"{read.results} results ({source})"]
    if left_out:
        scope.append(f"left out: {left_out}")
    wear_section = wear_html(wear) if wear is not None else ""
    html_path.write_text(html_page(programs, title, scope, png, wear_section), encoding="utf-8")
    return WrittenReport(
        html_path,
        png_path,
        programs,
        read.files,
        read.results,
        read.damaged,
        read.skipped,
        read.refused,
    )
