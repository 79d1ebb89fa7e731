"""A Foxglove WebSocket client for tests: the ``websockets`` package speaking the protocol.

The protocol (github.com/foxglove/ws-protocol, docs/spec.md): the server sends
``serverInfo`` and ``advertise`` (JSON text frames: channel id, topic,
encoding, schemaName, schema, schemaEncoding); the client sends ``subscribe``
(its own subscription id per channel id); the server then sends each message
as a binary frame: opcode ``0x01``, uint32 subscription id, uint64 log time
(ns), the payload (little endian). The foxglove-sdk server names this protocol
``foxglove.sdk.v1`` and refuses a client that offers only the older name
``foxglove.websocket.v1``; the client offers both, as a Foxglove app does.

:class:`FoxgloveClient` runs in a thread of its own (an asyncio loop) and keeps
every message of the topics it subscribed to. No product code imports it.
"""

from __future__ import annotations

import asyncio
import json
import struct
import threading
from collections.abc import Collection
from dataclasses import dataclass
from typing import Any

import websockets

SUBPROTOCOLS = ("foxglove.websocket.v1", "foxglove.sdk.v1")
MESSAGE_DATA = 0x01
_HEADER = struct.Struct("<BIQ")


@dataclass(frozen=True)
class ServedMessage:
    topic: str
    log_time_ns: int
    payload: bytes


class FoxgloveClient:
    """Connects to ``url``, subscribes to ``topics`` once advertised, keeps their messages."""

    def __init__(self, url: str, topics: Collection[str], connect_timeout_s: float = 30.0) -> None:
        self.url = url
        self.topics = set(topics)
        self.connect_timeout_s = connect_timeout_s
        self.subprotocol: str | None = None
        self.server_info: dict[str, Any] = {}
        self.channels: dict[str, dict[str, Any]] = {}  # by topic, as advertised
        self.messages: list[ServedMessage] = []
        self.error: BaseException | None = None
        self.subscribed = threading.Event()
        self._lock = threading.Lock()
        self._loop = asyncio.new_event_loop()
        self._stop: asyncio.Event | None = None
        self._thread = threading.Thread(target=self._run, name="foxglove-client", daemon=True)
        self._thread.start()

    def received(self, topic: str) -> list[ServedMessage]:
        with self._lock:
            return [message for message in self.messages if message.topic == topic]

    def close(self) -> None:
        if self._stop is not None:
            self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(10)

    def _run(self) -> None:
        try:
            self._loop.run_until_complete(self._session())
        except BaseException as err:  # seen by the test through .error
            self.error = err
            self.subscribed.set()
        finally:
            self._loop.close()

    async def _connect(self) -> Any:
        deadline = self._loop.time() + self.connect_timeout_s
        while True:
            try:
                offered = [websockets.Subprotocol(name) for name in SUBPROTOCOLS]
                return await websockets.connect(self.url, subprotocols=offered, max_size=None)
            except OSError:
                if self._loop.time() > deadline:
                    raise
                await asyncio.sleep(0.1)

    async def _session(self) -> None:
        self._stop = asyncio.Event()
        socket = await self._connect()
        async with socket:
            self.subprotocol = socket.subprotocol
            by_id: dict[int, str] = {}  # subscription id -> topic
            receiving = asyncio.ensure_future(socket.recv())
            stopping = asyncio.ensure_future(self._stop.wait())
            while True:
                done, _ = await asyncio.wait(
                    {receiving, stopping}, return_when=asyncio.FIRST_COMPLETED
                )
                if stopping in done:
                    receiving.cancel()
                    return
                frame = receiving.result()
                receiving = asyncio.ensure_future(socket.recv())
                if isinstance(frame, bytes):
                    opcode, subscription, log_time_ns = _HEADER.unpack_from(frame)
                    if opcode == MESSAGE_DATA and subscription in by_id:
                        message = ServedMessage(
                            by_id[subscription], log_time_ns, frame[_HEADER.size :]
                        )
                        with self._lock:
                            self.messages.append(message)
                    continue
                await self._on_text(socket, json.loads(frame), by_id)

    async def _on_text(self, socket: Any, text: dict[str, Any], by_id: dict[int, str]) -> None:
        if text["op"] == "serverInfo":
            self.server_info = text
        elif text["op"] == "advertise":
            wanted = []
            for channel in text["channels"]:
                self.channels[channel["topic"]] = channel
                if channel["topic"] in self.topics:
                    subscription = len(by_id) + 1
                    by_id[subscription] = channel["topic"]
                    wanted.append({"id": subscription, "channelId": channel["id"]})
            if wanted:
                await socket.send(json.dumps({"op": "subscribe", "subscriptions": wanted}))
            if self.topics <= set(by_id.values()):
                self.subscribed.set()
