"""The live Foxglove view: a Foxglove WebSocket server fed by the recorder's worker.

``serve recorder --foxglove-port N`` (or ``--view-only`` beside the line's
recorder) starts the ``foxglove-sdk``'s WebSocket server on
``--foxglove-host`` (default loopback) and advertises one channel per
(station, channel of :mod:`shared.contract.channels`) at once, so a client subscribes
before the first run starts. Each channel is the MCAP channel's twin: topic
the zenoh key (``boltwatch/st1/samples``), message encoding ``json``, schema
the codec's JSON schema (``jsonschema``) named ``boltwatch.<Type>``; a
layout made for the recordings works live, and the other way round.

What is served is what the recorder files, as the MCAP holds it: the same
payload bytes, the same log time, each sample of a
:class:`~shared.contract.messages.SampleBatch` as a sample of its own (the batch
channel itself is not advertised). Payloads the recorder refused (recorded
raw) and keys that are no channel are not served.

Nothing of the recording waits on a client: :meth:`FoxgloveLive.log` hands
bytes to the SDK, which copies them into each subscribed client's queue of
:data:`CLIENT_BACKLOG_MESSAGES` and sends from its own (Rust) threads; a
client too slow to keep up loses its oldest messages, never the recorder's
time. With no client subscribed to a channel a log is a check and a return.
The cost per sample with and without a client: ``docs/benchmarks.md``
(``tests/benchmarks/bench_foxglove_live.py``).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterable

import foxglove
from foxglove.websocket import WebSocketServer

from shared.contract import channels, json_schema
from shared.recordings import Received

LOG = logging.getLogger(__name__)

#: messages queued per client before its oldest are dropped: 2 s of one station's samples
CLIENT_BACKLOG_MESSAGES = 2048
#: the batch channel is served as its samples (on ``samples``), as the MCAP files hold it
NOT_SERVED = frozenset({channels.SAMPLE_BATCHES.topic})


def served_channels() -> list[channels.Channel[object]]:
    """The channels of :mod:`shared.contract.channels` a Foxglove client sees, per station."""
    return [channel for channel in channels.CHANNELS if channel.topic not in NOT_SERVED]


class FoxgloveLive:
    """A Foxglove WebSocket server with a channel per served station and channel."""

    def __init__(self, station_ids: Iterable[str], host: str, port: int) -> None:
        """Start serving on ``host``:``port`` (0: any free port, see :attr:`port`); raises
        what the SDK raises when the address cannot be bound."""
        self._context = foxglove.Context()  # not the process's global one: one view, one set
        self._channels: dict[str, foxglove.Channel] = {}
        schemas = {
            channel.schema_name: foxglove.Schema(
                name=channel.schema_name,
                encoding="jsonschema",
                data=json.dumps(json_schema(channel.message_type)).encode(),
            )
            for channel in served_channels()
        }
        for station in station_ids:
            for channel in served_channels():
                key = channel.key(station)
                self._channels[key] = foxglove.Channel(
                    key,
                    schema=schemas[channel.schema_name],
                    message_encoding="json",
                    context=self._context,
                )
        self._server: WebSocketServer | None = foxglove.start_server(
            name="boltwatch",
            host=host,
            port=port,
            context=self._context,
            message_backlog_size=CLIENT_BACKLOG_MESSAGES,
        )
        self.host = host
        self.port = self._server.port
        self.logged = 0  # messages handed to the server (whether or not a client took them)
        LOG.info(
            "Foxglove WebSocket: ws://%s:%d (%d channels)", host, self.port, len(self._channels)
        )

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def log(self, received: Received) -> None:
        """Serve one message the recorder filed (a refused or unknown one is not served)."""
        if received.message is None:
            return
        channel = self._channels.get(received.key)
        if channel is None:
            return
        channel.log(received.payload, log_time=received.log_time_ns)
        self.logged += 1

    def close(self) -> None:
        """Stop the server (clients are disconnected); safe to call twice."""
        server, self._server = self._server, None
        if server is None:
            return
        server.stop()
        for channel in self._channels.values():
            channel.close()
        LOG.info("Foxglove WebSocket stopped after %d messages", self.logged)
