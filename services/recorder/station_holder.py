"""One recorder per station: a second one refuses at start, in one line naming the first.

Two recorders of one station write the same run files: names taken twice,
messages not recorded, files left broken. So the line's recorder holds two
things, and a second one is refused (:class:`~shared.errors.ConfigError`, exit
status 2) when either is held already:

- the recordings folder's lock (``<recordings>/.recorder.lock``, an ``flock``
  the kernel drops when the holder dies, whatever kills it): the file says who
  holds it (pid, host, since when), so the refusal names it. Taken before
  anything else, it also makes the recorder that finishes a crash's unfinished
  files (:func:`~shared.recordings.mcap.finish_unfinished`) the only writer of
  the folder;
- the station's liveliness token ``boltwatch/<station>/health/recorder`` on
  the line, asked for before this recorder declares its own: a recorder on
  another host, writing another folder, holds it. A recorder whose host lost
  power keeps holding it until zenoh's lease of its session ends (``[zenoh]
  lease_s``, 10 s by default): the line keeps a silent session that long. So
  a holder that says nothing (no ``RecorderStats`` for :data:`SILENT_S`; a
  live one puts them once a second) is waited for, one WARNING line saying
  since when it holds the station and within how long its hold ends, at most
  the lease (and :data:`LEASE_MARGIN_S`): the new recorder starts once the
  token is gone, as a plant engineer restarting a recorder after a power loss
  expects. One that talks, or outlasts the lease, refuses the new recorder.

A ``--view-only`` recorder is a live view beside the line's recorder: it holds
neither and is refused by neither.
"""

from __future__ import annotations

import contextlib
import fcntl
import logging
import math
import os
import socket
import time
from collections.abc import Iterable, Iterator
from datetime import UTC, datetime
from pathlib import Path

import zenoh

from shared.contract import channels, keys
from shared.errors import ConfigError

LOG = logging.getLogger(__name__)

LOCK_NAME = ".recorder.lock"
#: how long to ask the line whether another recorder already holds a station
PEER_CHECK_TIMEOUT_S = 1.0
#: a holder that put no RecorderStats (once a second) for this long is taken as silent
SILENT_S = 2.5
#: the wait for a silent holder's token goes this far past zenoh's lease
LEASE_MARGIN_S = 2.0
#: how often the token is asked for while waiting
POLL_S = 0.5
#: the key of the lease in the station file
LEASE_KEY = "[zenoh] lease_s"
_REFUSAL_END = "one recorder records a station: stop it first, or give this one --view-only"


@contextlib.contextmanager
def recordings_folder_held(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s recorder lock until the context ends (or the process dies);
    ConfigError naming the holder when another process holds it."""
    path = folder / LOCK_NAME
    try:
        handle = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError as err:
        raise ConfigError(f"{path}: the recorder's lock cannot be opened: {err.strerror}") from err
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as err:
            raise ConfigError(
                f"{folder}: held by another recorder ({_holder(handle) or 'holder unknown'}, "
                f"{path}); one recorder writes a recordings folder: stop it first, or give "
                "this one --view-only"
            ) from err
        since = datetime.now(UTC).isoformat(timespec="seconds")
        holder = f"pid {os.getpid()} on {socket.gethostname()} since {since}\n"
        os.ftruncate(handle, 0)
        os.pwrite(handle, holder.encode(), 0)
        yield
    finally:
        os.close(handle)  # the lock goes with the descriptor; the file stays for the next


def _holder(handle: int) -> str:
    with contextlib.suppress(OSError):
        return os.pread(handle, 200, 0).decode(errors="replace").strip()
    return ""


def refuse_stations_recorded_elsewhere(
    session: zenoh.Session, station_ids: Iterable[str], lease_s: float = 10.0
) -> None:
    """Return once no other recorder holds a station of ``station_ids`` on the line, waiting
    for a silent holder's token at most zenoh's lease (``lease_s``); ConfigError naming the
    first station held by a recorder that talks, or whose hold outlasts the lease."""
    wanted = set(station_ids)
    heard: dict[str, str] = {}  # station -> when its holder's RecorderStats were heard

    def on_stats(sample: zenoh.Sample) -> None:
        station = keys.split_key(str(sample.key_expr))[0]
        if station in wanted:
            heard.setdefault(station, _clock())

    listening = session.declare_subscriber(channels.RECORDER.key("*"), on_stats)
    try:
        held = _held(session, wanted)
        if not held:
            return
        found_s, since = time.monotonic(), _clock()
        while time.monotonic() < found_s + SILENT_S:
            _refuse_if_talking(held, heard)
            time.sleep(0.05)
        deadline_s = found_s + lease_s + LEASE_MARGIN_S
        LOG.warning(
            "station(s) %s: held by a recorder on the line since %s (%s is alive) that has "
            "said nothing for %.1f s; if its host lost power, its hold ends within %.0f s "
            "(zenoh's lease, %s = %g s): waiting for it, then recording",
            _stations(held),
            since,
            held[0],
            SILENT_S,
            math.ceil(deadline_s - time.monotonic()),
            LEASE_KEY,
            lease_s,
        )
        while held:
            _refuse_if_talking(held, heard)
            if time.monotonic() >= deadline_s:
                raise ConfigError(
                    f"station(s) {_stations(held)} already have a recorder on the line "
                    f"({held[0]} is alive since {since}, silent, and its hold outlasted "
                    f"zenoh's lease of {lease_s:g} s, {LEASE_KEY}); {_REFUSAL_END}"
                )
            time.sleep(POLL_S)
            held = _held(session, wanted)
        LOG.info(
            "the hold on station(s) %s ended after %.1f s: recording",
            ", ".join(sorted(wanted)),
            time.monotonic() - found_s,
        )
    finally:
        listening.undeclare()


def _held(session: zenoh.Session, wanted: set[str]) -> list[str]:
    """The recorder tokens alive on the line of the stations ``wanted``, sorted."""
    replies = session.liveliness().get(
        keys.health_key("*", "recorder"), timeout=PEER_CHECK_TIMEOUT_S
    )
    return sorted(
        str(reply.ok.key_expr)
        for reply in replies
        if reply.ok is not None and keys.split_key(str(reply.ok.key_expr))[0] in wanted
    )


def _refuse_if_talking(held: list[str], heard: dict[str, str]) -> None:
    """ConfigError when the recorder of a station ``held`` put its RecorderStats."""
    for key in held:
        station = keys.split_key(key)[0]
        if station in heard:
            raise ConfigError(
                f"station(s) {_stations(held)} already have a recorder on the line ({key} is "
                f"alive, its RecorderStats heard at {heard[station]}); {_REFUSAL_END}"
            )


def _stations(held: list[str]) -> str:
    return ", ".join(keys.split_key(key)[0] for key in held)


def _clock() -> str:
    """The time of day now, as the log lines say it."""
    return datetime.now().strftime("%H:%M:%S")
