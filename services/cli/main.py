"""Entry point of the ``boltwatch`` console script.

Subcommands live in :mod:`services.cli.commands`, one module each (found by
name, see that package's docstring). How a command ends:

- a :class:`~shared.errors.BoltwatchError` (bad input or configuration):
  its one-line message, ``boltwatch COMMAND: ...``, and exit status 2;
- an ``OSError`` (a path that is missing, a folder, under a file, not
  writable, a full disk ...): one line naming the path and why
  (:mod:`services.cli.error_lines`: ``boltwatch export: /x/y.csv: folder /x
  does not exist``), exit status 2;
- standard output's reader gone (``boltwatch predict ... | head -1``): the
  output stops without a word, exit status 141 (128 + SIGPIPE, what a shell
  reports for any tool whose reader went away, seen with ``set -o pipefail``);
- Ctrl-C: exit status 130.

Started with standard output closed (``>&-``, a supervisor that closes it),
what a command prints goes to /dev/null: a service must run all the same.

Usage errors (an unknown option, a value argparse refuses) end with
argparse's usage line and message, exit status 2.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import signal
import sys
from collections.abc import Sequence
from types import ModuleType

from services.cli import commands
from services.cli.error_lines import os_error_line, silence_stdout, stdout_reader_gone
from shared.errors import BoltwatchError

#: exit status when standard output's reader went away: 128 + SIGPIPE, as a shell reports it
EXIT_READER_GONE = 128 + signal.SIGPIPE

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
    command = getattr(args, "command_label", args.command)  # "serve rig", not just "serve"
    if sys.stdout is None:  # started with standard output closed
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 (open for the life of the process)
    try:
        status = int(args.handler(args))
        sys.stdout.flush()  # a closed pipe fails here, not in Python's flush at exit
        return status
    except BoltwatchError as err:
        return _failed(command, str(err))
    except BrokenPipeError as err:
        if not stdout_reader_gone():
            return _failed(command, os_error_line(err))
        silence_stdout()
        return EXIT_READER_GONE
    except OSError as err:
        return _failed(command, os_error_line(err))
    except KeyboardInterrupt:
        return 130


def _failed(command: str, message: str) -> int:
    print(f"boltwatch {command}: {message}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
