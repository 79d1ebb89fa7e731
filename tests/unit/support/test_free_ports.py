"""The ports the tests give their routers and CAN buses are never the kernel's to hand out.

A port from the kernel's ephemeral range can be handed to another test (a bind
to port 0) or to an outgoing connection while a test's router is starting or
restarting, and the two tests then share a line (``tests/support/free_ports.py``).
"""

from __future__ import annotations

import socket

from tests.support.free_ports import DERIVED_SPAN, LOWEST_PORT, ephemeral_range
from tests.support.live_recorder import free_port
from tests.support.station_files import free_tcp_port, free_udp_port


def test_a_tests_ports_are_below_the_ephemeral_range_and_free() -> None:
    low, _high = ephemeral_range()
    tcp = [free_port() for _ in range(50)] + [free_tcp_port() for _ in range(50)]
    udp = [free_udp_port() for _ in range(50)]
    assert all(LOWEST_PORT <= port < low for port in tcp), tcp
    assert all(port >= LOWEST_PORT and port + DERIVED_SPAN < low for port in udp), udp
    for port in tcp:
        with socket.socket() as listener:
            listener.bind(("127.0.0.1", port))  # nothing holds it
    assert len(set(tcp)) > 90  # drawn, not handed out in turn


def test_a_port_the_kernel_picks_is_never_one_of_them() -> None:
    low, high = ephemeral_range()
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        assert low <= probe.getsockname()[1] <= high
