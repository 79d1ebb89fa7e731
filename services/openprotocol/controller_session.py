"""One Open Protocol session on a link: start, subscribe, ask, and hear what is pushed.

The integrator's side of the public specification, on one
:class:`~.controller_link.ControllerLink`:

- start: 0001 at the highest 0002 revision the codec implements, one lower on
  each 0004 error 97 (revision unsupported) down to 1; 0002 starts the session;
- subscriptions: 0060 at ``result_revision`` (one lower on error 97), 0008 for
  0900 traces when asked, 0070 alarms; each answered by 0005 (or 0004: counted,
  and the session goes on without that subscription, except 0060);
- asking: :meth:`request` writes a message and reads until its answer (the
  reply MID, or a 0004/0005 naming the MID asked); what the controller pushes
  meanwhile (0061, 0900, 0071...) goes to ``on_push`` as it comes;
- keep-alive: a 9999 at least every ``keep_alive_s``; the controller may
  mirror it or not. Once it has mirrored one, a controller silent for
  :data:`DEAD_AFTER_KEEP_ALIVES` keep-alive periods is a dead link; an answer
  that does not come within that time is one too (:class:`LinkLostError`);
- a frame the codec refuses (:class:`OpenProtocolError`) is counted and logged
  (``bad_messages`` for its shape: a length that does not fit its fields;
  ``refused_values`` for a field out of range) and the session goes on; a
  refused 0061 is still acknowledged (0062 names no id), so the controller
  does not re-send it and drop the link: the bridge fetches the id later
  (0064) and counts it again if refused again;
- stop: 0003.
"""

from __future__ import annotations

import contextlib
import logging
import time
from collections.abc import Callable
from typing import Any

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_link import ControllerLink, LinkLostError
from shared.openprotocol.codec import SUPPORTED_REVISIONS, UnknownMessage, decode, encode
from shared.openprotocol.dialect import Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.framing import Frame
from shared.openprotocol.session import (
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    KeepAlive,
)

LOG = logging.getLogger(__name__)

#: a controller that mirrors keep-alives and is silent this many periods is gone; an answer
#: that does not come within as long ends the link too
DEAD_AFTER_KEEP_ALIVES = 2.0
#: 0004 error code: the MID revision is not supported
REVISION_UNSUPPORTED = 97
#: MIDs answered by a 0004/0005 naming them, or by a reply MID of their own
RESULT_ACKNOWLEDGE_MID = 62

#: where what the controller pushes goes (a decoded message or a RefusedFrame)
Push = Callable[[Any], None]


class RefusedFrame:
    """A frame the codec refused: its MID and why (what ``on_push`` gets for it)."""

    def __init__(self, frame: Frame, error: OpenProtocolError) -> None:
        self.frame = frame
        self.error = error


class ControllerSession:
    """The integrator's session on one link."""

    def __init__(
        self,
        link: ControllerLink,
        counts: BridgeCounts,
        keep_alive_s: float,
        dialect: Dialect,
        on_push: Push,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._link = link
        self._counts = counts
        self._keep_alive_s = keep_alive_s
        self._dialect = dialect
        self._on_push = on_push
        self._clock = clock
        self.dead_after_s = DEAD_AFTER_KEEP_ALIVES * keep_alive_s
        now = clock()
        self._next_keep_alive = now + keep_alive_s
        self._heard = now
        self._mirrors = False  # the controller has mirrored a keep-alive on this link
        self.controller_name = ""
        self._garbage_seen = 0  # the link's reader counts since the link started
        self._bad_frames_seen = 0

    # -- writing -----------------------------------------------------------------------

    def send(self, message: Any, revision: int | None = None) -> None:
        self._link.send(encode(message, revision=revision, dialect=self._dialect))

    def keep_alive(self) -> None:
        """A 9999 now if one is due (at least every ``keep_alive_s``)."""
        now = self._clock()
        if now >= self._next_keep_alive:
            self.send(KeepAlive())
            self._counts.keep_alives_sent += 1
            self._next_keep_alive = now + self._keep_alive_s

    # -- the session's steps -----------------------------------------------------------

    def start(self) -> CommunicationStartAck:
        """0001 -> 0002 at the highest revision the controller takes."""
        for revision in sorted(SUPPORTED_REVISIONS[2], reverse=True):
            reply = self.request(CommunicationStart(revision=revision), {2})
            if isinstance(reply, CommunicationStartAck):
                self.controller_name = reply.controller_name.strip()
                return reply
            if isinstance(reply, CommandError) and reply.error_code != REVISION_UNSUPPORTED:
                raise LinkLostError(f"the controller refused MID 0001: error {reply.error_code}")
        raise LinkLostError("the controller takes no revision of MID 0001 this bridge implements")

    def subscribe(self, make: Callable[[int], Any], mid: int, highest: int) -> int | None:
        """Subscribe with ``make(revision)`` from ``highest`` down (error 97: one lower);
        the revision accepted, or None (a refusal other than 97, counted)."""
        revisions = sorted(
            (revision for revision in SUPPORTED_REVISIONS.get(mid, (1,)) if revision <= highest),
            reverse=True,
        )
        for revision in revisions:
            reply = self.request(make(revision), set())
            if isinstance(reply, CommandAccepted):
                return revision
            if isinstance(reply, CommandError) and reply.error_code != REVISION_UNSUPPORTED:
                self._counts.fault(
                    "controller error",
                    f"the controller refused MID {mid:04d} rev {revision}: error "
                    f"{reply.error_code}",
                )
                return None
        return None

    def request(
        self, message: Any, replies: set[int], expected_errors: tuple[int, ...] = ()
    ) -> Any:
        """Write ``message``; its answer: a message of a MID in ``replies``, or the 0004 /
        0005 naming its MID (a 0004 is counted unless its code is in ``expected_errors``).
        What comes meanwhile is pushed. LinkLostError when none comes."""
        asked = _mid_of(message)
        self.send(message)
        deadline = self._clock() + self.dead_after_s
        while True:
            for decoded in self._receive(deadline - self._clock()):
                if _answers(decoded, asked, replies):
                    if (
                        isinstance(decoded, CommandError)
                        and decoded.error_code not in expected_errors
                    ):
                        self._counts.controller_errors += 1
                    return decoded
                self._push(decoded)
            if self._clock() >= deadline:
                raise LinkLostError(f"no answer to MID {asked:04d} within {self.dead_after_s:g} s")

    def poll(self, timeout_s: float) -> None:
        """Read for up to ``timeout_s``; push what comes; keep-alive; notice silence."""
        for decoded in self._receive(timeout_s):
            self._push(decoded)
        if self._mirrors and self._clock() - self._heard > self.dead_after_s:
            raise LinkLostError(f"the controller has been silent for {self.dead_after_s:g} s")

    def stop(self) -> None:
        """0003: the session ends cleanly (the link may be gone already)."""
        with contextlib.suppress(LinkLostError, OpenProtocolError):
            self.send(CommunicationStop())

    # -- reading -----------------------------------------------------------------------

    def _receive(self, timeout_s: float) -> list[Any]:
        self.keep_alive()
        wait_s = min(max(0.0, timeout_s), max(0.0, self._next_keep_alive - self._clock()))
        frames = self._link.receive(wait_s)
        counts = self._counts
        counts.garbage_bytes += self._link.garbage_bytes - self._garbage_seen
        self._garbage_seen = self._link.garbage_bytes
        bad_frames = self._link.bad_frames - self._bad_frames_seen
        if bad_frames:
            self._bad_frames_seen = self._link.bad_frames
            counts.bad_messages += bad_frames
            counts.fault("bad message", "a message whose length does not fit: skipped")
        decoded: list[Any] = []
        if frames:
            self._heard = self._clock()
        for frame in frames:
            try:
                message = decode(frame, dialect=self._dialect)
            except OpenProtocolError as err:
                self._refused(frame, err)
                decoded.append(RefusedFrame(frame, err))
                continue
            if isinstance(message, KeepAlive):
                self._mirrors = True
                continue
            decoded.append(message)
        self.keep_alive()
        return decoded

    def _refused(self, frame: Frame, error: OpenProtocolError) -> None:
        if _is_shape(error):
            self._counts.bad_messages += 1
            self._counts.fault("bad message", f"bad message ignored: {error}")
        else:
            self._counts.refused_values += 1
            self._counts.fault("refused value", f"message refused: {error}")

    def _push(self, message: Any) -> None:
        if isinstance(message, CommandError):
            self._counts.controller_errors += 1
            self._counts.fault(
                "controller error",
                f"the controller sent error {message.error_code} for MID {message.mid:04d}",
            )
            return
        if isinstance(message, CommandAccepted):
            return  # an acceptance of nothing we wait for (a late one): nothing to do
        if isinstance(message, UnknownMessage):
            self._counts.fault(
                "bad message", f"MID {message.frame.mid:04d} is not one this bridge reads: ignored"
            )
            return
        self._on_push(message)


def _mid_of(message: Any) -> int:
    return int(message.MID)


def _answers(message: Any, asked: int, replies: set[int]) -> bool:
    if isinstance(message, UnknownMessage):
        return False
    if isinstance(message, CommandError | CommandAccepted):
        return int(message.mid) == asked
    if isinstance(message, RefusedFrame):  # the answer came, and was refused
        return message.frame.mid in replies
    return _mid_of(message) in replies


def _is_shape(error: OpenProtocolError) -> bool:
    """A refusal of the message's shape (its length, its parameter ids), not of a value."""
    why = error.why
    return (
        error.field == "length"
        or why.startswith("data ends")
        or "parameter id" in why
        or "bytes after" in why
    )
