"""Entry point of the ``boltwatch`` console script.

Subcommands live in :mod:`services.cli.commands`, one module each (found by
name, see that package's docstring). Any :class:`~shared.errors.BoltwatchError`
ends the program with its one-line message and exit status 2; Ctrl-C with 130.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence
from types import ModuleType

from services.cli import commands
from shared.errors import BoltwatchError

DESCRIPTION = """\
boltwatch: data acquisition and real-time stick-slip prediction for
bolt-tightening stations.

  boltwatch up                       run the simulated station end to end
  boltwatch serve SERVICE --config   run one service (rig, acquisition, ...)
  boltwatch predict TRACE.csv ...    run the predictor over a recorded trace

Run 'boltwatch COMMAND --help' for the options of a command.
"""


def command_modules() -> list[ModuleType]:
    """Every subcommand module, in name order."""
    names = sorted(info.name for info in pkgutil.iter_modules(commands.__path__))
    return [importlib.import_module(f"{commands.__name__}.{name}") for name in names]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="boltwatch",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in command_modules():
        sub = subparsers.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(sub)
        sub.set_defaults(handler=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except BoltwatchError as err:
        print(f"boltwatch {args.command}: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
