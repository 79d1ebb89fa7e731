"""A live predictor service on loopback for the tests: station files, feeds, collection.

One service serves two stations (pt1: program 1; pt2: only program 2, so a
pt2 run predicted with pt1's configuration would not be predicted at all);
pt3 is on the same zenoh network but not served. The fixtures
(``endpoint``, ``stations``, ``service``) are in this folder's conftest.
"""

from __future__ import annotations

import time
from pathlib import Path

import zenoh

from shared.contract import Sample, StopReasonName, ToolState, channels, codec, keys
from shared.runtime import declare_channel
from tests.support.live_recorder import has_subscribers, wait_until
from tests.support.paths import REPO

TARGET_N = 30_400.0
START_NS = 1_700_000_000_000_000_000
#: station id -> its only program id
PROGRAM_OF = {"pt1": 1, "pt2": 2}


def station_text(
    tmp_path: Path,
    station_id: str,
    program_id: int,
    endpoint: str,
    *,
    connect: bool = False,
    extra: str = "",
) -> str:
    """A station file's text: a peer listening on ``endpoint`` (``connect``: a client of the
    router there, as a station's services reach their line), ``extra`` sections at its end."""
    zenoh_endpoints = (
        f'mode = "client"\nconnect = ["{endpoint}"]'
        if connect
        else f'mode = "peer"\nlisten = ["{endpoint}"]'
    )
    return f"""
[station]
id = "{station_id}"
tool_id = 3
joint = "{REPO / "config/joints/paper-section-5-2.toml"}"
[can]
interface = "virtual"
channel = "{station_id}"
dbc = "{REPO / "config/can/station.dbc"}"
[zenoh]
{zenoh_endpoints}
[[programs]]
id = {program_id}
name = "test"
target_force_n = {TARGET_N}
motor_speed_rad_s = 0.5
start_force_n = 10000.0
max_torque_nm = 320.0
max_force_n = 75000.0
max_angle_deg = 150.0
max_time_s = 6.0
[predictor]
window_samples = 5
[recorder]
folder = "{tmp_path / "rec"}"
{extra}"""


def wait_for_token(session: zenoh.Session, key: str) -> None:
    for _ in range(100):
        if list(session.liveliness().get(key)):
            return
        time.sleep(0.05)
    raise AssertionError(f"no liveliness token {key}")


def wait_for_subscriber(publisher: zenoh.Publisher) -> None:
    wait_until(lambda: has_subscribers(publisher), f"a subscriber for {publisher.key_expr}", 4.0)


class StationFeed:
    """Publishers of one station's ``tool`` and ``samples``, as its acquisition declares them
    (:func:`~shared.runtime.declare_channel`: congestion control BLOCK, so a sample put in a
    burst under load waits instead of being dropped, as zenoh's default would)."""

    def __init__(self, session: zenoh.Session, station_id: str, wait: bool = True) -> None:
        self.station_id = station_id
        self.tool = declare_channel(session, channels.TOOL, station_id)
        self.samples = declare_channel(session, channels.SAMPLES, station_id)
        if wait:  # the predictor's subscribers must be known before the first put
            for publisher in (self.tool, self.samples):
                wait_for_subscriber(publisher)

    def state(
        self,
        run_id: int,
        program_id: int,
        name: str,
        at_ns: int,
        stop_command: StopReasonName | None = None,
    ) -> None:
        state = ToolState(self.station_id, run_id, 3, program_id, name, at_ns, stop_command)  # type: ignore[arg-type]
        self.tool.put(codec.encode(state))

    def sample(self, run_id: int, sequence: int, row: tuple[float, float, float, float]) -> None:
        t, torque, force, angle = row
        sample = Sample(
            self.station_id, run_id, sequence, START_NS + round(t * 1e9), torque, angle, force
        )
        self.samples.put(codec.encode(sample))

    def close(self) -> None:
        self.tool.undeclare()
        self.samples.undeclare()


def collect(
    subscriber: zenoh.Subscriber, until: set[str], timeout_s: float = 30.0, settle_s: float = 0.3
) -> dict[str, list[bytes]]:
    """Messages by ``<station>/<topic>`` until every key of ``until`` has one, then
    ``settle_s`` more (for whatever else was on its way), or until the timeout."""
    by_key: dict[str, list[bytes]] = {}
    deadline = time.monotonic() + timeout_s
    settled_at: float | None = None
    while time.monotonic() < deadline:
        if settled_at is None and until <= set(by_key):
            settled_at = time.monotonic() + settle_s
        if settled_at is not None and time.monotonic() > settled_at:
            break
        message = subscriber.try_recv()
        if message is None:
            time.sleep(0.01)
            continue
        station, topic = keys.split_key(str(message.key_expr))
        by_key.setdefault(f"{station}/{topic}", []).append(message.payload.to_bytes())
    return by_key
