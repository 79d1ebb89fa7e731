"""Ports for a test's router, peers and CAN bus that the kernel never hands to anyone else.

A port the kernel picks (a bind to port 0) comes from its ephemeral range
(``/proc/sys/net/ipv4/ip_local_port_range``, 32768-60999 by default), the range it
also takes the local port of every outgoing connection from, and every other
test's bind to port 0. Such a port is the test's only while something holds it:
between the pick and its router's start (seconds on a loaded machine), and
while a test's router is down (``test_router_restart.py`` kills it), another
test running beside it can be handed the same port. Then the two tests share
one line: a recording of this test's ``st1`` held another test's ``st1`` runs
(its Open Protocol results and its NaN samples, refused and recorded raw),
seen in ``tests/benchmarks/bench_recording_stress.py`` beside a system test run.

The ports here are drawn at random (from the operating system's randomness: a
test's seeded ``random`` would draw the same in two processes) below the
ephemeral range, where the kernel never picks one by itself, each checked
unbound for TCP on loopback and for UDP on every address: two tests that both
draw here meet only if they draw the same port while neither holds it yet. A
UDP port leaves room after it for the stations derived from the file
(:func:`shared.config.derive_stations` gives station ``i`` the port + ``i``).
"""

from __future__ import annotations

import random
import socket
from pathlib import Path

#: the lowest port drawn (above the well-known and most registered services' ports)
LOWEST_PORT = 20_000
#: ports kept free after a UDP port, for the stations derived from its file
DERIVED_SPAN = 256
_RANGE_FILE = Path("/proc/sys/net/ipv4/ip_local_port_range")
_DRAW = random.SystemRandom()


def ephemeral_range() -> tuple[int, int]:
    """The kernel's ephemeral ports, first and last (Linux's default where not readable)."""
    try:
        low, high = (int(part) for part in _RANGE_FILE.read_text().split())
    except (OSError, ValueError):
        return 32768, 60999
    return low, high


def _bindable(port: int, kind: int, host: str) -> bool:
    with socket.socket(socket.AF_INET, kind) as probe:
        try:
            probe.bind((host, port))
        except OSError:
            return False
    return True


def _draw(span: int) -> int:
    """A port below the ephemeral range, ``span`` ports after it below it too, each unbound
    for TCP on loopback and UDP everywhere."""
    highest = ephemeral_range()[0] - span - 1
    for _ in range(1000):
        port = _DRAW.randint(LOWEST_PORT, highest)
        if all(
            _bindable(candidate, socket.SOCK_STREAM, "127.0.0.1")
            and _bindable(candidate, socket.SOCK_DGRAM, "")
            for candidate in range(port, port + span + 1)
        ):
            return port
    raise RuntimeError(f"no free port between {LOWEST_PORT} and {highest}")


def free_tcp_port() -> int:
    """A TCP port on 127.0.0.1 that nothing holds now and the kernel hands to no one."""
    return _draw(0)


def free_udp_port() -> int:
    """A UDP port for a CAN multicast bus, and the :data:`DERIVED_SPAN` after it."""
    return _draw(DERIVED_SPAN)
