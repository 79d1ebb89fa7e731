"""``boltwatch health SERVICE --config FILE [FILE ...]``: a container health check.

Exit 0 when SERVICE is alive for every station named, 1 when it is not, 2
when the line's router cannot be reached (or a file is bad). "Alive" is the
service's liveliness token ``boltwatch/<st>/health/<service>``: a token
vanishes when its process or its zenoh session dies, so a hung container
whose session is gone fails the check. ``health router`` only opens a client
session to the router of the station file (that is the router's liveness).
"""

from __future__ import annotations

import argparse

from services.cli.command_options import add_station_file_option

NAME = "health"
HELP = "exit 0 if a service is alive for the stations named (for container health checks)"

CHECKED_SERVICES = (
    "router",
    "rig",
    "acquisition",
    "predictor",
    "recorder",
    "viewer",
    "dashboard",
    "opcua",
    "openprotocol",
)
CONNECT_TIMEOUT_MS = 2000
LIVELINESS_TIMEOUT_S = 2.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("service", choices=CHECKED_SERVICES, help="the service to check")
    add_station_file_option(
        parser,
        "station file(s): the service must be alive for each station; the first "
        "file's [zenoh] connect names the router",
        several=True,
    )


def run(args: argparse.Namespace) -> int:
    import sys

    from shared.config import load_any_line
    from shared.contract import keys
    from shared.errors import ConfigError
    from shared.runtime import client_config, open_from

    stations = load_any_line(args.config)
    section = stations[0].config.zenoh
    connect = section.connect
    if not connect:
        raise ConfigError(f"{stations[0].path}: zenoh.connect: health needs a router to ask")
    # As the file's services connect (with mutual TLS: this container's certificate).
    with open_from(client_config(section, CONNECT_TIMEOUT_MS)) as s:
        if args.service == "router":
            print(f"router at {', '.join(connect)}: reachable")
            return 0
        alive = set()
        for reply in s.liveliness().get(
            keys.health_key("*", args.service), timeout=LIVELINESS_TIMEOUT_S
        ):
            if reply.ok is not None:
                alive.add(keys.split_key(str(reply.ok.key_expr))[0])
    missing = [st.station_id for st in stations if st.station_id not in alive]
    if missing:
        print(f"{args.service}: not alive for {', '.join(missing)}", file=sys.stderr)
        return 1
    print(f"{args.service}: alive for {', '.join(st.station_id for st in stations)}")
    return 0
