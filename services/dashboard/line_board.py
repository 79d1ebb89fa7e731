"""What the line's page shows, kept up to date from what arrives: pure, thread-safe.

The zenoh side (:mod:`.board_feed`) feeds every message of the stations
served, the liveliness tokens and the recorder's wear replies; the web side
(:mod:`.web_app`) asks for :meth:`LineBoard.snapshot`, one JSON-ready dict.

What ``boltwatch status`` collects is reused, not copied
(:class:`shared.line_status.station_status.StatusCollector`), twice:

- one collector for the whole life of the page: the latest of everything
  (last run, decision, result, recorder and predictor health with their age,
  the bus, a controller bridge and its active alarm);
- one per window of :data:`WINDOW_S` (as one ``boltwatch status --listen-s``):
  the services alive at its end and the sample rate over it.

Beside them, what status does not keep: the last :data:`HISTORY` results and
stop reasons of each station (a multi-spindle station's: the last :data:`HISTORY` cycles of
every spindle, each result with its spindle, its cycle's sync id and that cycle's common
result once its ``CycleResult`` came on ``cycles``; a single-spindle station's results say
none of them), the alerts of every alert channel of
:mod:`shared.contract.channels` (a topic ending in ``alert``: the recorder's
``wear/alert`` and ``quality/alert``, and any other a service adds, shown by its fields), and the
wear of each tool from the recorder's ``wear`` queryable against the
station's ``recorder.wear_service_threshold``; and for the whole line, the tools due soonest
with their forecasts and charts (:mod:`.tools_due`).
"""

from __future__ import annotations

import dataclasses
import threading
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from services.dashboard.tools_due import ToolSeen, tools_due, tools_seen
from shared.config import StationPlace
from shared.contract import CycleResult, RunSummary, TighteningResult, channels, decode, keys
from shared.errors import InputError
from shared.line_status import KNOWN_SERVICES, StationStatus, StatusCollector, last_result

#: results, stop reasons and alerts kept per station
HISTORY = 10
#: seconds of one window: services alive and sample rate (as ``boltwatch status --listen-s``)
WINDOW_S = 2.0
_NS = 1_000_000_000

#: every alert channel of the line: topic -> channel (the channel table, read at start)
ALERT_CHANNELS = {c.topic: c for c in channels.CHANNELS if c.topic.endswith("alert")}
#: fields that tell two alerts of one channel apart (the latest of each is kept)
_ALERT_IDENTITY = ("tool_id", "program_id", "kind", "figure")


@dataclass(frozen=True, slots=True)
class StationSetting:
    """A station the page shows, from its station file."""

    station: str
    wear_threshold: float | None  # recorder.wear_service_threshold; None: none set
    place: StationPlace = field(default_factory=StationPlace)  # [station] plant, line, name


@dataclass(frozen=True, slots=True)
class ToolWearLine:
    """One tool's wear as the recorder's ``wear`` queryable said it."""

    tool_id: int
    runs: int
    runs_since_service: int
    intensity_since_service: float
    total_intensity: float


@dataclass
class _History:
    """What status does not keep, of one station."""

    results: deque[TighteningResult] = field(default_factory=lambda: deque(maxlen=HISTORY))
    summaries: deque[RunSummary] = field(default_factory=lambda: deque(maxlen=HISTORY))
    cycles: dict[int, CycleResult] = field(default_factory=dict)  # sync id -> common result
    alerts: dict[tuple[Any, ...], dict[str, Any]] = field(default_factory=dict)
    wear: list[ToolWearLine] = field(default_factory=list)
    tools: list[ToolSeen] = field(default_factory=list)  # with their outlooks: the forecasts
    wear_error: str | None = "no reply from the recorder yet"
    wear_ns: int = 0


class LineBoard:
    """Feed it from any thread; :meth:`snapshot` is what the page draws."""

    def __init__(self, stations: list[StationSetting], started_ns: int, router: str = "") -> None:
        self._settings = {setting.station: setting for setting in stations}
        self._router = router  # the endpoints the page's session reaches the line by
        self._router_reachable: bool | None = None  # None: not known yet
        self._router_since_ns = started_ns
        self._lock = threading.Lock()
        self._latest = StatusCollector()
        self._window = StatusCollector()
        self._window_started_ns = started_ns
        self._started_ns = started_ns
        self._last_window: dict[str, StationStatus] = {}
        self._windows_closed = 0
        self._history = {station: _History() for station in self._settings}

    @property
    def stations(self) -> list[str]:
        return list(self._settings)

    def message(self, key: str, payload: bytes, received_ns: int) -> bool:
        """One message of a station served; True when the page should be redrawn now
        (a result, a run's end, an alert, an alarm), False when the next window will do."""
        try:
            station, topic = keys.split_key(key)
        except ValueError:
            return False
        history = self._history.get(station)
        if history is None:
            return False
        with self._lock:
            self._latest.message(key, payload, received_ns)
            self._window.message(key, payload, received_ns)
            try:
                return _remember(history, topic, payload)
            except InputError:
                return False  # counted by the collectors (unreadable messages)

    def close_window(self, alive_keys: list[str], now_ns: int) -> None:
        """The window ends: ``alive_keys`` are the liveliness tokens that exist now."""
        with self._lock:
            for key in alive_keys:
                self._window.alive(key)
            listened_s = (now_ns - self._window_started_ns) / _NS
            report = self._window.report("", listened_s, now_ns)
            self._last_window = {status.station: status for status in report.stations}
            self._window = StatusCollector()
            self._window_started_ns = now_ns
            self._windows_closed += 1

    def wear_reply(self, station: str, payload: bytes, now_ns: int) -> None:
        """The recorder's reply to ``boltwatch/<station>/wear`` (InputError: not one)."""
        tools = parse_wear_reply(payload)
        seen = tools_seen(station, payload, self._settings[station].wear_threshold)
        with self._lock:
            history = self._history[station]
            history.wear, history.wear_error, history.wear_ns = tools, None, now_ns
            history.tools = seen

    def wear_failed(self, station: str, reason: str, now_ns: int) -> None:
        """No usable wear reply for ``station`` (the last good table stays, with the reason)."""
        with self._lock:
            history = self._history[station]
            history.wear_error, history.wear_ns = reason, now_ns

    def router_link(self, reachable: bool, now_ns: int) -> None:
        """Whether the page's zenoh session reaches the line (its router) now."""
        with self._lock:
            if reachable != self._router_reachable:
                self._router_reachable, self._router_since_ns = reachable, now_ns

    def snapshot(self, now_ns: int) -> dict[str, Any]:
        """The page's data: every station served, in the order of its files."""
        with self._lock:
            latest = {
                status.station: status for status in self._latest.report("", 0.0, now_ns).stations
            }
            stations = [
                _station_view(
                    self._settings[name],
                    latest.get(name),
                    self._last_window.get(name),
                    self._windows_closed > 0,
                    self._history[name],
                    now_ns,
                )
                for name in self._settings
            ]
            router = {
                "endpoints": self._router,
                "reachable": self._router_reachable,
                "for_s": (now_ns - self._router_since_ns) / _NS,
            }
            seen = [tool for name in self._settings for tool in self._history[name].tools]
        return {
            "now_ns": now_ns,
            "window_s": WINDOW_S,
            "router": router,
            "stations": stations,
            "tools_due": tools_due(seen, now_ns),
        }


def _remember(history: _History, topic: str, payload: bytes) -> bool:
    if topic == channels.RESULTS.topic:
        result = decode(TighteningResult, payload)
        if result.spindle is not None and HISTORY * result.spindle > (history.results.maxlen or 0):
            # a multi-spindle station: the last cycles of every spindle
            history.results = deque(history.results, maxlen=HISTORY * result.spindle)
            history.summaries = deque(history.summaries, maxlen=HISTORY * result.spindle)
        history.results.appendleft(result)
        return True
    if topic == channels.RUNS.topic:
        history.summaries.appendleft(decode(RunSummary, payload))
        return True
    if topic == channels.CYCLES.topic:
        cycle = decode(CycleResult, payload)
        history.cycles[cycle.sync_id] = cycle
        while len(history.cycles) > 2 * HISTORY:  # the oldest cycle's result goes
            del history.cycles[next(iter(history.cycles))]
        return True
    if topic in ALERT_CHANNELS:
        alert = decode(ALERT_CHANNELS[topic].message_type, payload)
        fields = dataclasses.asdict(alert)
        identity = (topic, *(fields.get(name) for name in _ALERT_IDENTITY))
        history.alerts[identity] = {
            "topic": topic,
            "time_ns": fields.get("time_ns", 0),
            "text": alert_text(topic, fields),
        }
        return True
    return topic == channels.ALARMS.topic


def alert_text(topic: str, fields: dict[str, Any]) -> str:
    """One line for a person: a wear or quality alert in words, any other alert by its
    fields."""
    if topic == channels.WEAR_ALERT.topic:
        return (
            f"tool {fields['tool_id']} due for service: intensity since service "
            f"{fields['intensity_since_service']:.3g} >= threshold {fields['threshold']:.3g} "
            f"({fields['runs_since_service']} runs)"
        )
    if topic == channels.QUALITY_ALERT.topic:
        return f"{fields['kind']}: {fields['text']}{'' if fields['active'] else ' (cleared)'}"
    shown = {name: value for name, value in fields.items() if name not in ("station", "time_ns")}
    return ", ".join(f"{name.replace('_', ' ')} {_shown(value)}" for name, value in shown.items())


def _shown(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def parse_wear_reply(payload: bytes) -> list[ToolWearLine]:
    """The tool lines of a ``wear`` reply (the recorder's JSON); InputError when not one."""
    import json

    try:
        body = json.loads(payload)
        return [
            ToolWearLine(
                tool_id=int(line["tool_id"]),
                runs=int(line["runs"]),
                runs_since_service=int(line["runs_since_service"]),
                intensity_since_service=float(line["intensity_since_service"]),
                total_intensity=float(line["total_intensity"]),
            )
            for line in body["tools"]
        ]
    except (ValueError, KeyError, TypeError) as err:
        raise InputError(f"not a wear reply ({type(err).__name__}: {err})") from err


def _station_view(
    setting: StationSetting,
    latest: StationStatus | None,
    window: StationStatus | None,
    window_closed: bool,
    history: _History,
    now_ns: int,
) -> dict[str, Any]:
    latest_view = dataclasses.asdict(latest) if latest is not None else {}
    if window is not None:
        services = window.services
    else:  # silent for a whole window, no token: every service down (none: not asked yet)
        services = dict.fromkeys(KNOWN_SERVICES, False) if window_closed else {}
    return {
        "station": setting.station,
        "name": setting.place.name,
        "plant": setting.place.plant,
        "line": setting.place.line,
        "services": services,
        "samples_per_s": window.samples_per_s if window is not None else None,
        "bus_samples_per_s": window.bus_samples_per_s if window is not None else None,
        "last_run": latest_view.get("last_run"),
        "recorder": latest_view.get("recorder"),
        "predictor": latest_view.get("predictor"),
        "bus": latest_view.get("bus"),
        "bridge": latest_view.get("bridge"),
        "spools": latest_view.get("spools", []),
        "unreadable_messages": latest_view.get("unreadable_messages", 0),
        "results": [_result_view(result, now_ns, history.cycles) for result in history.results],
        "stops": [_stop_view(summary, now_ns) for summary in history.summaries],
        "wear": [_wear_view(tool, setting.wear_threshold) for tool in history.wear],
        "wear_threshold": setting.wear_threshold,
        "wear_error": history.wear_error,
        "alerts": sorted(history.alerts.values(), key=lambda a: -int(a["time_ns"]))[:HISTORY],
    }


def _result_view(
    result: TighteningResult, now_ns: int, cycles: dict[int, CycleResult]
) -> dict[str, Any]:
    shown = last_result(result, now_ns)
    assert shown is not None  # a result in, a line out
    view = dataclasses.asdict(shown)
    view |= {
        "tightening_id": result.tightening_id,
        "tool_id": result.tool_id,
        "program": result.program_name or f"program {result.program_id}",
        "stop_reason": result.stop_reason,
        "time_ns": result.time_ns,
    }
    if result.sync_id is not None:  # a spindle's run of a multi-spindle cycle
        cycle = cycles.get(result.sync_id)
        view |= {
            "spindle": result.spindle,
            "sync_id": result.sync_id,
            "cycle": None if cycle is None else _cycle_view(cycle),  # None: not come yet
        }
    return view


def _cycle_view(cycle: CycleResult) -> dict[str, Any]:
    return {
        "sync_id": cycle.sync_id,
        "spindles": len(cycle.spindles),
        "result": cycle.result,
        "nok_reasons": cycle.nok_reasons,
        "part_id": cycle.part_id,
    }


def _stop_view(summary: RunSummary, now_ns: int) -> dict[str, Any]:
    return {
        "run_id": summary.run_id,
        "tool_id": summary.tool_id,
        "stop_reason": summary.stop_reason or f"tool ({summary.tool_state})",
        "late_decision": summary.late_decision,
        # a final stage (None: the run had none), and its pulses back to the target
        "final_stage_s": summary.final_stage_s,
        "pulses": summary.pulses,
        "error_pct": summary.error_pct,
        "events": summary.events,
        "age_s": round((now_ns - summary.ended_ns) / _NS, 3),
    } | ({} if summary.spindle is None else {"spindle": summary.spindle})


def _wear_view(tool: ToolWearLine, threshold: float | None) -> dict[str, Any]:
    used = None if not threshold else tool.intensity_since_service / threshold
    return dataclasses.asdict(tool) | {
        "threshold": threshold,
        "used": used,  # fraction of the threshold taken since the last service
        "due": used is not None and used >= 1.0,
    }
