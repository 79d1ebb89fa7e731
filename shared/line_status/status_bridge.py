"""What ``boltwatch status`` shows of a station's controller bridge: the link, faults, alarms.

From the latest :class:`~shared.contract.messages.BridgeStats` on
``boltwatch/<st>/openprotocol`` (once a second from ``boltwatch serve
openprotocol``): whether the controller link is up, to which ``host:port``,
the revision of MID 0061 in use, the results published and the last
tightening id, how its 0900 samples read, and the bridge's counters that are
not zero (:data:`FAULTS`); the alarm active on the controller: the one the
bridge's latest stats carry (it keeps the controller's alarm state, whether
or not status heard the alarm), or, without stats in the window, the newest
still active of the :class:`~shared.contract.messages.ControllerAlarm` heard on
``boltwatch/<st>/alarms`` (each error code's latest word counts; a status
saying no alarm is active clears them all). A station without a bridge shows
none of these lines. Collected by
:mod:`shared.line_status.station_status`, printed by :mod:`services.cli.station_status_text`.

A bridge station (one whose bridge holds ``health/openprotocol`` or spoke on
``openprotocol`` in the window) runs no acquisition, predictor or rig of its
own: its services are :data:`BRIDGE_SERVICES`, the bridge, its link to the
controller (``controller``: up while the latest BridgeStats says connected)
and the recorder (:func:`station_services`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.contract import BridgeStats, ControllerAlarm, channels, decode

_NS = 1_000_000_000

#: the topics this module reads
TOPICS = (channels.OPENPROTOCOL.topic, channels.ALARMS.topic)
#: the services of a bridge station, in display order (``controller``: the bridge's link)
BRIDGE_SERVICES = ("openprotocol", "controller", "recorder")

#: fault counters of BridgeStats shown when not zero, with their words
FAULTS = (
    ("link_drops", "link drops"),
    ("results_filled", "results filled after a reconnect"),
    ("repeated_results", "repeated results"),
    ("traces_without_result", "traces without a result"),
    ("garbage_bytes", "garbage bytes"),
    ("bad_messages", "bad messages"),
    ("refused_values", "refused values"),
    ("controller_errors", "controller errors"),
    ("results_without_traces", "results without curves"),
    ("traces_refused", "curves refused"),
    ("results_given_up", "results given up"),
    ("epochs", "new controller epochs"),
    ("clock_refused", "controller times refused"),
)


@dataclass
class BridgeSeen:
    """What a station's bridge said during the window."""

    stats: BridgeStats | None = None
    stats_received_ns: int = 0
    alarms: dict[str, ControllerAlarm] = field(default_factory=dict)  # latest per error code

    def take(self, topic: str, payload: bytes, received_ns: int) -> None:
        """One message of :data:`TOPICS` (InputError: not a valid one)."""
        if topic == channels.OPENPROTOCOL.topic:
            self.stats = decode(BridgeStats, payload)
            self.stats_received_ns = received_ns
            return
        alarm = decode(ControllerAlarm, payload)
        if alarm.kind == "status" and not alarm.active and not alarm.error_code:
            self.alarms.clear()  # the controller says no alarm is active
            return
        latest = self.alarms.get(alarm.error_code)
        if latest is None or alarm.time_ns >= latest.time_ns:
            self.alarms[alarm.error_code] = alarm


def is_bridge_station(alive: set[str], seen: BridgeSeen) -> bool:
    """A station whose bridge holds its token or spoke in the window."""
    return "openprotocol" in alive or seen.stats is not None


def station_services(
    alive: set[str], seen: BridgeSeen, can_services: tuple[str, ...]
) -> dict[str, bool]:
    """Service -> alive: the station's own services first (a bridge station's
    :data:`BRIDGE_SERVICES`, else ``can_services``), each alive or not, then any other
    service alive, by name."""
    alive = set(alive)
    known = can_services
    if is_bridge_station(alive, seen):
        known = BRIDGE_SERVICES
        if seen.stats is not None and seen.stats.connected:
            alive.add("controller")
    services = {service: service in alive for service in known}
    services.update(dict.fromkeys(sorted(alive - set(known)), True))
    return services


@dataclass(frozen=True)
class ActiveAlarm:
    error_code: str
    kind: str  # raised | acknowledged | status
    text: str
    controller_ready: bool | None
    tool_ready: bool | None
    age_s: float  # since the controller's time of the alarm


@dataclass(frozen=True)
class BridgeStatus:
    controller: str  # host:port
    connected: bool
    result_revision: int | None
    connects: int
    results: int
    last_tightening_id: int | None
    faults: dict[str, int]  # the fault counters that are not zero, in FAULTS order
    last_error: str | None
    age_s: float | None  # since the latest BridgeStats was received; None: none (alarms only)
    alarm: ActiveAlarm | None  # the newest active alarm
    trace_reading: str | None = None  # how the controller's 0900 samples read right


def bridge_status(seen: BridgeSeen, now_ns: int) -> BridgeStatus | None:
    """None: no bridge spoke in the window (no BridgeStats, no alarm)."""
    stats = seen.stats
    if stats is None and not seen.alarms:
        return None
    if stats is not None:
        newest = stats.active_alarm
    else:
        active = [alarm for alarm in seen.alarms.values() if alarm.active]
        newest = max(active, key=lambda alarm: alarm.time_ns) if active else None
    alarm = None
    if newest is not None:
        alarm = ActiveAlarm(
            newest.error_code,
            newest.kind,
            newest.text,
            newest.controller_ready,
            newest.tool_ready,
            round((now_ns - newest.time_ns) / _NS, 3),
        )
    if stats is None:
        return BridgeStatus("?", False, None, 0, 0, None, {}, None, None, alarm)
    return BridgeStatus(
        controller=stats.controller,
        connected=stats.connected,
        result_revision=stats.result_revision,
        connects=stats.connects,
        results=stats.results,
        last_tightening_id=stats.last_tightening_id,
        faults={name: getattr(stats, name) for name, _ in FAULTS if getattr(stats, name)},
        last_error=stats.last_error,
        age_s=round((now_ns - seen.stats_received_ns) / _NS, 3),
        alarm=alarm,
        trace_reading=stats.trace_reading,
    )


def bridge_lines(status: BridgeStatus | None) -> list[tuple[str, str]]:
    """(label, text) lines for a person; none for a station without a bridge."""
    if status is None:
        return []
    return [
        ("controller", _link_text(status)),
        ("bridge faults", _faults_text(status)),
        ("alarm", _alarm_text(status.alarm)),
    ]


def _link_text(status: BridgeStatus) -> str:
    if status.age_s is None:
        return "- (no bridge stats in the window: bridge down?)"
    revision = "-" if status.result_revision is None else str(status.result_revision)
    last = "-" if status.last_tightening_id is None else str(status.last_tightening_id)
    link = "connected to" if status.connected else "NOT CONNECTED to"
    text = (
        f"{link} {status.controller}, MID 0061 revision {revision}, {status.results} results, "
        f"last tightening {last} ({status.connects} connects, {status.age_s:.1f} s ago)"
    )
    if status.trace_reading:
        text += f"; curves read {status.trace_reading}"
    if status.last_error:
        text += f"; last error: {status.last_error}"
    return text


def _faults_text(status: BridgeStatus) -> str:
    if status.age_s is None:
        return "-"
    words = dict(FAULTS)
    return ", ".join(f"{count} {words[name]}" for name, count in status.faults.items()) or "none"


def _alarm_text(alarm: ActiveAlarm | None) -> str:
    if alarm is None:
        return "none active"
    text = f"{alarm.error_code} {alarm.kind}, {alarm.age_s:.1f} s ago"
    if alarm.text:
        text += f": {alarm.text}"
    ready = [
        f"{what} {'ready' if flag else 'NOT ready'}"
        for what, flag in (("controller", alarm.controller_ready), ("tool", alarm.tool_ready))
        if flag is not None
    ]
    if ready:
        text += f" ({', '.join(ready)})"
    return text
