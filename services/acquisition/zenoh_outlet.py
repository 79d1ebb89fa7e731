"""Publish the acquisition's output on zenoh (``samples``, ``tool``, ``bus``).

Through the station's :class:`~shared.runtime.queued_publisher.QueuedPublisher`:
the CAN thread only queues (it is the stop path), a thread of the
publisher's own encodes and puts, in order. An edge station's publisher
sends the samples in batches on ``sample_batches`` (the line only records
them); a line-placed station's one message per sample on ``samples``.

While the session has no router (it restarts, the network is cut) zenoh has
nowhere to send a sample. With the station's spool on (``[spool]``, the
default) nothing is lost: the spool sends it again when the line's recorder
is back, and ``unsent_samples`` (reported in BusStats) counts only what will
never arrive: samples the spool failed to keep or dropped to keep its bound.
Without a spool such a sample is lost and counted. Each outage is logged once
when it starts and once, with its length and its count, when it ends. The
check on the 1 kHz path is one attribute read
(:class:`~shared.runtime.zenoh_session.RouterLink`).
"""

from __future__ import annotations

import logging

import zenoh

from shared.contract import BusStats, Sample, ToolState
from shared.runtime import QueuedPublisher, RouterLink

LOG = logging.getLogger(__name__)


class ZenohOutlet:
    """The acquisition's outlet on the station's queued publisher."""

    def __init__(self, session: zenoh.Session, publisher: QueuedPublisher) -> None:
        self._publisher = publisher
        self._publish = publisher.publish
        self._spooling = publisher.spooling
        self._unspooled_unsent = 0  # without a spool: published while no router was reached
        self._unsent_at_outage_start = 0
        self.link = RouterLink(session, self._link_changed)
        if not self.link.connected:
            LOG.warning(
                "zenoh: no router yet; %s",
                "the spool keeps what is measured"
                if self._spooling
                else "samples are counted as unsent until one is reached",
            )

    @property
    def unsent_samples(self) -> int:
        """Samples that will never reach the line (counted since the process started)."""
        return self._unspooled_unsent + self._publisher.lost_samples

    def sample(self, sample: Sample) -> None:
        if not self._spooling and not self.link.connected:
            self._unspooled_unsent += 1
        self._publish(sample)

    def tool_state(self, state: ToolState) -> None:
        self._publish(state)

    def bus_stats(self, stats: BusStats) -> None:
        self._publish(stats)

    def _link_changed(self, connected: bool, outage_s: float) -> None:
        if connected:
            lost = self.unsent_samples - self._unsent_at_outage_start
            LOG.warning(
                "zenoh: router back after %.1f s; %d samples unsent in that outage (%d in all)%s",
                outage_s,
                lost,
                self.unsent_samples,
                "; the spool sends the rest again" if self._spooling else "",
            )
        else:
            self._unsent_at_outage_start = self.unsent_samples
            LOG.warning(
                "zenoh: router lost; reconnecting, %s",
                "samples kept in the spool meanwhile"
                if self._spooling
                else "samples are counted as unsent meanwhile",
            )

    def close(self) -> None:
        self.link.close()
