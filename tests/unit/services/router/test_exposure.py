"""A line listening in plain tcp beyond loopback says loudly what anyone on the network can do."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from services.router.service import exposure_warning
from tests.support.live_recorder import free_port


@pytest.mark.parametrize(
    ("endpoints", "exposed"),
    [
        (["tcp/127.0.0.1:7447"], False),
        (["tcp/localhost:7447", "udp/[::1]:7447"], False),
        (["tls/0.0.0.0:7447"], False),
        (["tcp/0.0.0.0:7447"], True),
        (["tcp/127.0.0.1:7447", "tcp/10.0.0.5:7447"], True),
    ],
)
def test_only_a_plain_endpoint_beyond_loopback_is_exposed(
    endpoints: list[str], exposed: bool
) -> None:
    warning = exposure_warning(endpoints)
    assert (warning is not None) == exposed
    if warning is not None:
        assert "stop a tool" in warning and "wear ledger" in warning and "TLS" in warning


def test_the_router_warns_at_start_when_it_listens_unprotected() -> None:
    """Consider making a line on a non-loopback address warn loudly without TLS."""
    endpoint = f"tcp/0.0.0.0:{free_port()}"
    router = subprocess.Popen(
        [sys.executable, "-m", "services.cli", "serve", "router", "--listen", endpoint],
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert router.stderr is not None
        deadline = time.monotonic() + 20.0
        line = ""
        while time.monotonic() < deadline and "UNPROTECTED LINE" not in line:
            line = router.stderr.readline()
        assert "WARNING" in line and f"plain {endpoint} with no TLS" in line, line
    finally:
        router.terminate()
        router.wait(10)
