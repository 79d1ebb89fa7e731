"""Publish the acquisition's output on zenoh (``samples``, ``tool``, ``bus``)."""

from __future__ import annotations

import zenoh

from shared import keys
from shared.codec import encode
from shared.messages import BusStats, Sample, ToolState


class ZenohOutlet:
    """One declared publisher per key; samples and run states share a priority so
    that a run's ``done`` never overtakes its last samples."""

    def __init__(self, session: zenoh.Session, station_id: str) -> None:
        def publisher(topic: str) -> zenoh.Publisher:
            return session.declare_publisher(
                keys.station_key(station_id, topic),
                congestion_control=zenoh.CongestionControl.BLOCK,
                express=True,  # no batching: the stop path is latency-critical
            )

        self._samples = publisher(keys.SAMPLES)
        self._tool = publisher(keys.TOOL)
        self._bus = publisher(keys.BUS)

    def sample(self, sample: Sample) -> None:
        self._samples.put(encode(sample))

    def tool_state(self, state: ToolState) -> None:
        self._tool.put(encode(state))

    def bus_stats(self, stats: BusStats) -> None:
        self._bus.put(encode(stats))

    def close(self) -> None:
        for publisher in (self._samples, self._tool, self._bus):
            publisher.undeclare()
