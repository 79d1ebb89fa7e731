"""Tightenings the store keeps aside: those whose figures cannot be a measurement.

One rule says what a result is (:mod:`shared.quality.plausible_result`: a
final torque of 1e308 Nm is none), and it is applied where results enter the
store (:meth:`~.results_store.ResultsStore.add`), whoever writes them: the
recorder, ``results rebuild``, the recorder's catch-up. Such a tightening goes
into ``refused_tightenings`` (the columns of ``tightenings``, its steps with
the others) instead of ``tightenings``: no reader counts it (``results``,
``report``, OPC UA, the part search read ``tightenings`` only), nothing of it
is lost, and the retention policy finds it stored. Each is named in the words
``report`` uses for the same result read from a file (:func:`refused_line`),
whenever a reader asks which results of a question were refused
(:meth:`~.results_store.ResultsStore.refused`).

:data:`IMPLAUSIBLE_SQL` is the same rule over the store's columns: the
migration to version 4 moves the rows an older boltwatch stored into
``refused_tightenings`` with it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from shared.quality import figures_fault, refusal_line
from shared.quality.plausible_result import EVENTS_LIMIT, FIGURE_LIMITS, INTENSITY_LIMIT

#: each judged figure's value and window columns, in the order of FIGURE_LIMITS
JUDGED_COLUMNS = (
    ("torque_nm", "torque_min_nm", "torque_max_nm"),
    ("angle_deg", "angle_min_deg", "angle_max_deg"),
    ("force_n", "force_min_n", "force_max_n"),
)
#: true for a row whose figures cannot be a measurement, as :func:`figures_fault` judges
#: them; NULL (not measured) is never beyond (NOT BETWEEN of a NULL is NULL, not true)
IMPLAUSIBLE_SQL = " OR ".join(
    [
        f"{column} NOT BETWEEN {-limit!r} AND {limit!r}"
        for (_, limit, _), columns in zip(FIGURE_LIMITS, JUDGED_COLUMNS, strict=True)
        for column in columns
    ]
    + [f"events > {EVENTS_LIMIT}", f"process_intensity NOT BETWEEN 0 AND {INTENSITY_LIMIT!r}"]
)
#: what a line names, in the order :func:`refused_line` takes them
LINE_COLUMNS = (
    "station, run_id, tool_id, "
    + ", ".join(column for columns in JUDGED_COLUMNS for column in columns)
    + ", events, process_intensity"
)


def refused_line(row: Sequence[Any]) -> str:
    """The line naming a refused tightening, from its :data:`LINE_COLUMNS`: the line
    :func:`shared.quality.refusal_line` gives for the same result read from a file."""
    station, run_id, tool_id, *figures = row
    judged = [tuple(figures[index : index + 3]) for index in (0, 3, 6)]
    why = figures_fault(judged, figures[9], figures[10]) or "beyond the bounds when it was stored"
    return refusal_line(str(station), int(run_id), int(tool_id), why)
