"""Command-line options of ``boltwatch serve dashboard`` (light: no heavy imports)."""

from __future__ import annotations

import argparse

from services.dashboard.viewer_links import viewer_template

DEFAULT_LISTEN = "127.0.0.1:8080"


def host_port(text: str) -> tuple[str, int]:
    """``HOST:PORT`` (``[::1]:8080`` for IPv6) -> (host, port); argparse's error otherwise."""
    host, colon, port = text.rpartition(":")
    host = host.removeprefix("[").removesuffix("]")
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise argparse.ArgumentTypeError(
            f"expected HOST:PORT with a port from 1 to 65535, e.g. {DEFAULT_LISTEN} (got {text!r})"
        )
    return host, int(port)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The stations come from their files (``--config``); the page's address from --listen."""
    parser.epilog = (
        "One web page for the line: per station the services alive, the sample rate, the "
        "last results (OK/NOK) and stop reasons, each tool's wear against "
        "recorder.wear_service_threshold, and alerts; live, without reloading. Its search "
        "box finds every tightening of a part (a VIN, a work piece) in the results store of "
        "the station files; a click on a result opens its run's curve, read from its "
        "recording (torque over angle and time, preload, windows, stick-slip events, the "
        "stop decision), beside the part's other runs or its program's recent ones, with "
        "its files to download. Open http://HOST:PORT/ in a browser; nothing on it comes "
        "from the internet."
    )
    parser.add_argument(
        "--listen",
        type=host_port,
        default=host_port(DEFAULT_LISTEN),
        metavar="HOST:PORT",
        help=f"where the page is served (default {DEFAULT_LISTEN}; 0.0.0.0:8080 in a container)",
    )
    viewers = parser.add_argument_group(
        "outside viewers (a link from a run's view; none by default: the line may be offline)"
    )
    viewers.add_argument(
        "--rerun-viewer",
        type=viewer_template,
        metavar="URL",
        help="Rerun's web viewer, {url} where the .rrd's address goes, e.g. "
        "'https://app.rerun.io/version/0.41.0/?url={url}' (the rrd's version's viewer)",
    )
    viewers.add_argument(
        "--foxglove",
        type=viewer_template,
        metavar="URL",
        help="Foxglove, {url} where the .mcap's address goes, e.g. "
        "'https://app.foxglove.dev/~/view?ds=remote-file&ds.url={url}'",
    )
