"""``boltwatch serve router``: a zenoh session in router mode.

Stations connect to it as clients (``[zenoh] mode = "client"``). In a plant
the official ``eclipse/zenoh`` router image does the same job (see
docker-compose.yml); this one needs nothing but the Python wheel.

With ``--connect`` it meshes with another line's router (a plant of several
lines): the two routers route every declaration, put, query and liveliness
token between their lines, so ``boltwatch status`` and ``boltwatch wear``
answer for the whole plant from any line. A peer router that is not there
yet is retried for ever (every ``RECONNECT_PERIOD_MAX_MS`` at most).

With ``--tls-*`` it takes only TLS connections from services whose
certificate the line's CA signed (mutual TLS); with ``--access-control`` it
enforces zenoh's access control, e.g. only a station's predictor may put
its decisions (``docs/reference/access-control.md``). Listening in plain tcp on anything but
loopback, it warns loudly at start: any node that reaches the port can then
stop a tool, write the wear ledger and read the whole line.
"""

from __future__ import annotations

import argparse
import logging
import threading
from pathlib import Path

import zenoh

from shared.errors import ConfigError
from shared.runtime import ServiceSkeleton, TlsFiles, zenoh_config, zenoh_reason

LOG = logging.getLogger(__name__)

DEFAULT_LISTEN = "tcp/127.0.0.1:7447"
_LOOPBACK_HOSTS = ("127.", "[::1]", "localhost")


def exposure_warning(endpoints: list[str]) -> str | None:
    """What an unauthenticated node can do on this line, when a plain endpoint is not loopback."""
    exposed = [
        endpoint
        for endpoint in endpoints
        if not endpoint.startswith("tls/")
        and not endpoint.split("/", 1)[-1].startswith(_LOOPBACK_HOSTS)
    ]
    if not exposed:
        return None
    return (
        f"the line listens in plain {', '.join(exposed)} with no TLS: any node that reaches "
        "it can stop a tool (a StopDecision), write the wear ledger (a RunSummary) and read "
        "every sample, unauthenticated. On a plant network run the router with mutual TLS "
        "and access control (--listen tls/HOST:PORT --tls-root-ca --tls-cert --tls-key "
        "--access-control; docs/how-to/compose-and-tls.md)"
    )


def router_config(args: argparse.Namespace) -> zenoh.Config:
    """The router's zenoh.Config; bad TLS or access-control options are ConfigErrors."""
    endpoints = args.listen or [DEFAULT_LISTEN]
    peers = getattr(args, "connect", None) or []
    tls = _tls_files(args, [*endpoints, *peers])
    config = zenoh_config("router", connect=peers, listen=endpoints, tls=tls)
    if args.access_control is not None:
        _insert_access_control(config, args.access_control)
    return config


def _tls_files(args: argparse.Namespace, endpoints: list[str]) -> TlsFiles | None:
    given = {
        "--tls-root-ca": args.tls_root_ca,
        "--tls-cert": args.tls_cert,
        "--tls-key": args.tls_key,
    }
    uses_tls = any(endpoint.startswith("tls/") for endpoint in endpoints)
    if not any(given.values()):
        if uses_tls:
            raise ConfigError("a tls/ endpoint needs --tls-root-ca, --tls-cert and --tls-key")
        return None
    missing = [option for option, path in given.items() if path is None]
    if missing:
        raise ConfigError(f"TLS needs {', '.join(missing)} as well")
    if not uses_tls:
        raise ConfigError("--tls-* options given but no --listen tls/HOST:PORT endpoint")
    for option, path in given.items():
        _check_readable(option, path)
    return TlsFiles(args.tls_root_ca, args.tls_cert, args.tls_key)


def _check_readable(option: str, path: Path) -> None:
    try:
        with path.open("rb") as handle:
            handle.read(1)
    except OSError as err:
        raise ConfigError(f"{option} {path}: cannot be read: {err.strerror}") from err


def _insert_access_control(config: zenoh.Config, path: Path) -> None:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise ConfigError(f"--access-control {path}: cannot be read: {err.strerror}") from err
    except UnicodeDecodeError as err:
        raise ConfigError(
            f"--access-control {path}: not a text file (byte {err.start}: {err.reason})"
        ) from err
    try:
        config.insert_json5("access_control", text)
    except zenoh.ZError as err:
        raise ConfigError(
            f"{path}: not a zenoh access_control section (enabled, default_permission, "
            f"rules, subjects, policies): {zenoh_reason(err)}"
        ) from err


def main(args: argparse.Namespace) -> int:
    config = router_config(args)
    endpoints = args.listen or [DEFAULT_LISTEN]
    with ServiceSkeleton("router") as skeleton:
        skeleton.open_session_from(config)
        LOG.info("zenoh router listening on %s", ", ".join(endpoints))
        if peers := getattr(args, "connect", None):
            LOG.info("meshed with the routers of other lines at %s", ", ".join(peers))
        warning = exposure_warning(endpoints)
        if warning is not None:
            LOG.warning("UNPROTECTED LINE: %s", warning)
        if args.access_control is not None:
            LOG.info("access control from %s", args.access_control)

        def work(stop: threading.Event) -> None:
            stop.wait()  # the session routes on zenoh's threads

        return skeleton.run(work)
