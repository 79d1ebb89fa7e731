"""One Open Protocol session on a link: start, subscribe, ask, and hear what is pushed.

The integrator's side of the public specification, on one
:class:`~.controller_link.ControllerLink`:

- start: 0001 at the highest 0002 revision the codec implements, one lower on
  each 0004 error 97 (revision unsupported) down to 1; 0002 starts the session;
- asking: :meth:`request` writes a message and reads until its answer (a reply
  MID, or a 0004/0005 naming the MID asked: for 0008/0009 the specification's
  0005 names the MID subscribed for, and some controllers name 0008 itself, so
  either answers); :meth:`request_highest` asks from a highest revision down,
  one lower on error 97 (an expected answer: neither a fault nor a controller
  error). What the controller pushes meanwhile (0061, 0900, 0071...) goes to
  ``on_push`` in the order it came, also what shared a TCP read with the answer;
- an answer that does not come within the dead-link time of the last message
  the controller wrote (a controller busy writing long curves is not a silent
  one; a keep-alive does not count), at most :data:`ANSWER_WAIT_LIMIT` times
  that long: for a request the session cannot go on without (0001, 0060) the link
  is dead (:class:`LinkLostError`); for any other it is counted and logged,
  and the session goes on without it;
- keep-alive: a 9999 at least every ``keep_alive_s``; the controller may
  mirror it or not. Once it has mirrored one, a controller silent for
  :data:`DEAD_AFTER_KEEP_ALIVES` keep-alive periods is a dead link;
- a frame the codec refuses (:class:`OpenProtocolError`) is counted and logged
  (``bad_messages`` for its shape, ``refused_values`` for a field) and pushed
  as a :class:`RefusedFrame`; the session goes on;
- stop: the service's ``stop`` event ends any wait within :data:`READ_SLICE_S`
  (:class:`SessionStoppedError`), then 0003.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Collection
from typing import Any

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_link import ControllerLink, LinkLostError
from shared.openprotocol import (
    SUPPORTED_REVISIONS,
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    Dialect,
    Frame,
    KeepAlive,
    OpenProtocolError,
    UnknownMessage,
    decode,
    encode,
)

LOG = logging.getLogger(__name__)

#: a controller that mirrors keep-alives and is silent this many periods is gone; an answer
#: the session cannot go on without that does not come within as long ends the link too
DEAD_AFTER_KEEP_ALIVES = 2.0
#: 0004 error code: the MID revision is not supported
REVISION_UNSUPPORTED = 97
#: the longest one read waits while an answer is awaited (the stop event is looked at between)
READ_SLICE_S = 0.1
#: a controller that keeps writing other messages gets this many dead-link times to answer
ANSWER_WAIT_LIMIT = 5.0

#: where what the controller pushes goes (a decoded message or a RefusedFrame)
Push = Callable[[Any], None]


class SessionStoppedError(Exception):
    """The service is stopping: the session ends where it is (not a fault)."""


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
        stop: threading.Event | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._link = link
        self._counts = counts
        self._keep_alive_s = keep_alive_s
        self._dialect = dialect
        self._on_push = on_push
        self._stop = stop if stop is not None else threading.Event()
        self._clock = clock
        self.dead_after_s = DEAD_AFTER_KEEP_ALIVES * keep_alive_s
        now = clock()
        self._next_keep_alive = now + keep_alive_s
        self._heard = now
        self._mirrors = False  # the controller has mirrored a keep-alive on this link
        self.controller_name = ""
        self._garbage_seen = 0  # the link's reader counts since the link started
        self._bytes_heard = 0
        self._bad_frames_seen = 0
        #: messages read with an answer and not handled yet (they came after it)
        self._unread: deque[Any] = deque()

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
        highest = max(SUPPORTED_REVISIONS[CommunicationStart.MID])
        reply = self.request_highest(
            lambda revision: CommunicationStart(revision=revision), {2}, highest, required=True
        )[1]
        if isinstance(reply, CommunicationStartAck):
            self.controller_name = reply.controller_name.strip()
            return reply
        if isinstance(reply, CommandError) and reply.error_code != REVISION_UNSUPPORTED:
            raise LinkLostError(f"the controller refused MID 0001: error {reply.error_code}")
        raise LinkLostError("the controller takes no revision of MID 0001 this bridge implements")

    def subscribe(
        self, make: Callable[[int], Any], highest: int, *, required: bool = False
    ) -> int | None:
        """Subscribe with ``make(revision)`` from ``highest`` down; the revision accepted, or
        None (refused: counted; not answered: counted, or LinkLostError when ``required``)."""
        revision, reply = self.request_highest(make, set(), highest, required=required)
        return revision if isinstance(reply, CommandAccepted) else None

    def request_highest(
        self,
        make: Callable[[int], Any],
        replies: set[int],
        highest: int,
        *,
        required: bool = False,
        expected_errors: Collection[int] = (),
    ) -> tuple[int, Any]:
        """Ask ``make(revision)`` from the highest revision implemented up to ``highest``
        down, one lower on error 97; the revision last asked and its answer (None: none came).

        A 0004 other than 97 (and not in ``expected_errors``) is counted and logged."""
        mid = int(make(1).MID)
        revisions = sorted(
            (r for r in SUPPORTED_REVISIONS.get(mid, (1,)) if r <= highest), reverse=True
        ) or [1]
        reply: Any = None
        for revision in revisions:
            reply = self.request(
                make(revision),
                replies,
                expected_errors=(REVISION_UNSUPPORTED, *expected_errors),
                required=required,
            )
            if isinstance(reply, CommandError) and reply.error_code == REVISION_UNSUPPORTED:
                LOG.info(
                    "%s takes no MID %04d rev %d: asking rev %d",
                    self._counts.controller,
                    mid,
                    revision,
                    revision - 1,
                )
                continue
            if isinstance(reply, CommandError) and reply.error_code not in expected_errors:
                self._counts.fault(
                    "controller error",
                    f"the controller refused MID {mid:04d} rev {revision}: error "
                    f"{reply.error_code} ({reply.error_name})",
                )
            return revision, reply
        self._counts.fault(
            "controller error",
            f"the controller takes no revision of MID {mid:04d} up to {highest}",
        )
        return revisions[-1], reply

    def request(
        self,
        message: Any,
        replies: set[int],
        expected_errors: Collection[int] = (),
        *,
        required: bool = True,
    ) -> Any:
        """Write ``message``; its answer: a message of a MID in ``replies``, or the 0004 /
        0005 naming its MID (a 0004 is counted unless its code is in ``expected_errors``).

        What comes meanwhile is pushed. No answer within the dead-link time of the
        last message heard (see the module's text): LinkLostError when
        ``required``, else None (counted and logged)."""
        asked = _mid_of(message)
        naming = {asked, *_subscribed_mid(message)}
        self.send(message)
        deadline = self._clock() + self.dead_after_s
        latest = self._clock() + ANSWER_WAIT_LIMIT * self.dead_after_s
        while True:
            if self._stop.is_set():
                raise SessionStoppedError
            messages = self._take_unread() or self._receive(
                min(READ_SLICE_S, deadline - self._clock())
            )
            if messages or self._link.pending_bytes:  # it is writing: the answer may follow
                deadline = min(self._clock() + self.dead_after_s, latest)
            for index, decoded in enumerate(messages):
                if _answers(decoded, naming, replies):
                    self._unread.extendleft(reversed(messages[index + 1 :]))
                    if (
                        isinstance(decoded, CommandError)
                        and decoded.error_code not in expected_errors
                    ):
                        self._counts.controller_errors += 1
                    return decoded
                self._push(decoded)
            if self._clock() >= deadline:
                why = f"no answer to MID {asked:04d} within {self.dead_after_s:g} s"
                if required:
                    raise LinkLostError(why)
                self._counts.fault("controller error", f"{why}: going on without it")
                return None

    def poll(self, timeout_s: float) -> None:
        """Read for up to ``timeout_s``; push what comes; keep-alive; notice silence."""
        for decoded in self._take_unread() or self._receive(timeout_s):
            self._push(decoded)
        if self._mirrors and self._clock() - self._heard > self.dead_after_s:
            raise LinkLostError(f"the controller has been silent for {self.dead_after_s:g} s")

    def stop(self) -> None:
        """0003: the session ends cleanly (the link may be gone already)."""
        with contextlib.suppress(LinkLostError, OpenProtocolError):
            self.send(CommunicationStop())

    # -- reading -----------------------------------------------------------------------

    def _take_unread(self) -> list[Any]:
        messages = list(self._unread)
        self._unread.clear()
        return messages

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
        if self._link.bytes_received != self._bytes_heard:  # a byte is a sign of life
            self._bytes_heard = self._link.bytes_received
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


def _subscribed_mid(message: Any) -> tuple[int, ...]:
    """The data MID a 0008/0009 subscribes to (its 0005/0004 may name it), else none."""
    if _mid_of(message) in (8, 9):
        return (int(message.mid),)
    return ()


def _answers(message: Any, naming: set[int], replies: set[int]) -> bool:
    if isinstance(message, UnknownMessage):
        return False
    if isinstance(message, CommandError | CommandAccepted):
        return int(message.mid) in naming
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
