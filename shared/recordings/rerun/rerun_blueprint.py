"""The Rerun entity paths of a run and the viewer layout that opens on them.

Entity tree of one run recording (``run_time``: seconds since the run's
``ToolState(running)``; ``log_time``: the message's own wall-clock time, the
MCAP ``publish_time``)::

    torque/torque_nm              every sample (line)
    torque/peaks                  T_max,j of each stick-slip event (points)
    torque/predicted_peaks        predicted next peaks, every horizon (points)
    torque/stop                   torque at the stop decision (marker)
    force/force_n                 every sample carrying a force (line)
    force/plateaus                F_j of each event (points)
    force/predicted_plateaus      predicted next plateaus (points)
    force/stop                    force at the stop decision (marker)
    angle/angle_deg               every sample (line)
    model/f_ss_hz, model/k1..k3   per event
    intensity/event, /process     I_j and I_process per event (eqs. 67, 68)
    log                           tool state, stop decision, run summary (text)

The blueprint: torque and force with their events on top, the model figures
and intensity in the middle, the text log at the bottom.
"""

from __future__ import annotations

import functools

import rerun as rr
import rerun.blueprint as rrb

APPLICATION_ID = "boltwatch"
RUN_TIME = "run_time"  # duration timeline, seconds since run start
LOG_TIME = "log_time"  # timestamp timeline, the message's own time

TORQUE = "torque/torque_nm"
PEAKS = "torque/peaks"
PREDICTED_PEAKS = "torque/predicted_peaks"
TORQUE_STOP = "torque/stop"
TORQUE_STAGE = "torque/stage"  # a final stage's commands: switch, pulse, halt, finish
FORCE = "force/force_n"
PLATEAUS = "force/plateaus"
PREDICTED_PLATEAUS = "force/predicted_plateaus"
FORCE_STOP = "force/stop"
ANGLE = "angle/angle_deg"
F_SS = "model/f_ss_hz"
K_PATHS = ("model/k1", "model/k2", "model/k3")
EVENT_INTENSITY = "intensity/event"
PROCESS_INTENSITY = "intensity/process"
LOG = "log"

_LINES: dict[str, tuple[str, tuple[int, int, int]]] = {
    TORQUE: ("torque (N·m)", (31, 119, 180)),
    FORCE: ("force (N)", (44, 160, 44)),
    ANGLE: ("angle (°)", (127, 127, 127)),
    F_SS: ("f_ss (Hz)", (148, 103, 189)),
    K_PATHS[0]: ("K1", (214, 39, 40)),
    K_PATHS[1]: ("K2", (255, 127, 14)),
    K_PATHS[2]: ("K3", (140, 86, 75)),
    EVENT_INTENSITY: ("I_j", (23, 190, 207)),
    PROCESS_INTENSITY: ("I_process", (188, 189, 34)),
}
_POINTS: dict[str, tuple[str, tuple[int, int, int], rr.components.MarkerShape, float]] = {
    PEAKS: ("peak", (214, 39, 40), rr.components.MarkerShape.Down, 6.0),
    PREDICTED_PEAKS: ("predicted peak", (255, 127, 14), rr.components.MarkerShape.Cross, 5.0),
    TORQUE_STOP: ("stop", (200, 0, 200), rr.components.MarkerShape.Asterisk, 10.0),
    TORQUE_STAGE: ("final stage", (0, 150, 136), rr.components.MarkerShape.Diamond, 8.0),
    PLATEAUS: ("plateau", (214, 39, 40), rr.components.MarkerShape.Square, 5.0),
    PREDICTED_PLATEAUS: ("predicted plateau", (255, 127, 14), rr.components.MarkerShape.Cross, 5.0),
    FORCE_STOP: ("stop", (200, 0, 200), rr.components.MarkerShape.Asterisk, 10.0),
}


def log_series_styles(stream: rr.RecordingStream) -> None:
    """Static names, colours and markers of every series (once per recording)."""
    for path, style in _series_styles():
        stream.log(path, style, static=True)


@functools.cache
def _series_styles() -> list[tuple[str, rr.SeriesLines | rr.SeriesPoints]]:
    """The styles, built once: building one costs Rerun more than logging it."""
    styles: list[tuple[str, rr.SeriesLines | rr.SeriesPoints]] = [
        (path, rr.SeriesLines(names=name, colors=color)) for path, (name, color) in _LINES.items()
    ]
    styles += [
        (path, rr.SeriesPoints(names=name, colors=color, markers=marker, marker_sizes=size))
        for path, (name, color, marker, size) in _POINTS.items()
    ]
    return styles


def run_blueprint() -> rrb.Blueprint:
    """Torque and force with events (top), f_ss and K1-K3, intensities, decisions (bottom)."""
    top = rrb.Vertical(
        rrb.TimeSeriesView(
            name="Torque: samples, peaks, predicted peaks, stop",
            origin="/torque",
            plot_legend=rrb.Corner2D.LeftTop,
        ),
        rrb.TimeSeriesView(
            name="Force: samples, plateaus, predicted plateaus, stop",
            origin="/force",
            plot_legend=rrb.Corner2D.LeftTop,
        ),
    )
    # one view per constant and per intensity: K2 (~1e4) and I_process (~1e6)
    # would flatten K1, K3 and I_j on a shared axis
    constants = rrb.Horizontal(
        rrb.TimeSeriesView(name="f_ss (Hz)", origin="/model", contents=F_SS),
        *(
            rrb.TimeSeriesView(name=path.rsplit("/", 1)[-1].upper(), contents=f"+ {path}")
            for path in K_PATHS
        ),
    )
    intensities = rrb.Horizontal(
        rrb.TimeSeriesView(name="I_j (eq. 67)", contents=f"+ {EVENT_INTENSITY}"),
        rrb.TimeSeriesView(name="I_process (eq. 68)", contents=f"+ {PROCESS_INTENSITY}"),
        rrb.TimeSeriesView(name="Angle (°)", origin="/angle"),
    )
    bottom = rrb.TextLogView(name="Decisions and summary", origin=f"/{LOG}")
    return rrb.Blueprint(
        rrb.Vertical(top, constants, intensities, bottom, row_shares=[3, 1.2, 1.2, 1]),
        rrb.TimePanel(timeline=RUN_TIME, state="collapsed"),
        collapse_panels=True,
    )
