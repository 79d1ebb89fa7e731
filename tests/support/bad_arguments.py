"""What the no-traceback tests feed ``boltwatch``: every command and argument, read from the
parser, and values that are wrong in every way a path, a number or a word can be.

A command's arguments are found by walking ``build_parser()`` (``serve`` has a
sub-command per service), so a new command or option is covered without a
change here. Values come from pools by the argument's kind (path, whole
number, number, word, choice) and, for paths, by direction (``--out`` and
friends are written, the rest read). Files live in a fresh :class:`Workspace`
per case: a good station file (its router a closed loopback port, 0.2 s
connect timeout, its recordings folder under a regular file so ``up`` can
never start a process), a good trace, a good recording, and every kind of bad
path.

Commands that could block (a service that runs until stopped, a wait for a
router) are *fused*: each case gives one of their arguments a value that must
be refused before anything is opened (:data:`FUSE`). Only :data:`OFFLINE`
commands, which read and write files and end, get cases without a fuse.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import random
import re
import stat
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from services.cli.main import build_parser
from shared.contract import Sample, encode, write_trace
from shared.recordings import classify
from shared.recordings.mcap import McapSink
from tests.support.paths import JOINT_5_2
from tests.support.station_files import write_station

#: a log line of a service (``boltwatch serve`` logs to stderr): "12:00:00 rig   INFO    ..."
LOG_LINE = re.compile(r"^\d\d:\d\d:\d\d \S+ +(DEBUG|INFO|WARNING|ERROR|CRITICAL) ")

#: commands that only read and write files and then end: safe to run with good arguments
OFFLINE = frozenset(
    {"predict", "simulate", "import", "model", "recover", "export", "inspect", "wear"}
)

#: arguments that name a file or folder to be written
OUTPUT_DESTS = frozenset({"out", "plot", "csv_dir", "recordings"})

#: good files by argument name (relative to the workspace). No controller run for ``import``:
#: it is driven with bad files only (its good runs, and recordings under a regular file,
#: are tests/unit/services/cli/test_import_replay.py and tests/unit/recorder/test_import_*.py).
GOOD_INPUTS = {
    "config": "station.toml",
    "joint": "joint.toml",
    "trace": "good.csv",
    "recording": "good.mcap",
    "file": "good.mcap",
    "recordings": "recordings",
}

#: paths that are wrong for anything read: missing, in a missing folder, a folder, under a
#: regular file, empty, binary, unreadable (EIO even for root), a name too long, text that
#: is no format we read
BAD_INPUTS = (
    "missing.csv",
    "no-folder/run.mcap",
    "a-folder",
    "a-file.txt/run.mcap",
    "empty.toml",
    "binary.bin",
    "/proc/self/mem",
    "n" * 300,
    "a-file.txt",
)

#: paths that are wrong for anything written (``full`` is a /dev/full of the workspace's own
#: where the test may make device files: every write fails with ENOSPC)
BAD_OUTPUTS = (
    "no-folder/out.png",
    "a-folder",
    "a-file.txt/out.png",
    "n" * 300 + ".png",
    "full",
)

BAD_INTS = ("-1", "0", "99999999999999999999999", "-99999999999999999999", "nan", "1.5", "")
BAD_FLOATS = ("-1", "0", "-0", "1e-300", "nan", "inf", "1e308", "1e400", "")
BAD_WORDS = ("notanendpoint", "", "tcp/", "x" * 300, "st1", "ü\u202e")

#: values every argument of its kind must refuse before anything is opened
FUSE = {
    "path": ("a-file.txt/run.mcap", "n" * 300),
    "int": ("-1", "nan", "1.5"),
    "float": ("-1", "nan", "inf", "0"),
    "word": ("notanendpoint", "tcp/", ""),
}


@dataclass(frozen=True)
class Argument:
    """One argument of one command, as the parser declares it."""

    flag: str | None  # "--out"; None for a positional
    dest: str
    kind: str  # "path", "int", "float", "word", "choice" or "switch"
    choices: tuple[str, ...]
    required: bool
    exclusive_with: frozenset[str]  # dests of a mutually exclusive group it is in

    @property
    def is_output(self) -> bool:
        return self.dest in OUTPUT_DESTS

    def render(self, value: str | None) -> list[str]:
        """The argv words for ``value`` (a switch: present when ``value`` is not None)."""
        if self.kind == "switch":
            return [self.flag] if self.flag and value is not None else []
        words = [value if value is not None else ""]
        return [self.flag, *words] if self.flag else words


def commands() -> dict[tuple[str, ...], argparse.ArgumentParser]:
    """Every runnable command, ``("export",)``, ``("serve", "rig")``..., with its parser."""
    found: dict[tuple[str, ...], argparse.ArgumentParser] = {}

    def walk(parser: argparse.ArgumentParser, path: tuple[str, ...]) -> None:
        subparsers = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subparsers and path:
            found[path] = parser
        for action in subparsers:
            for name, sub in action.choices.items():
                walk(sub, (*path, name))

    walk(build_parser(), ())
    return found


def arguments(parser: argparse.ArgumentParser) -> list[Argument]:
    """The arguments of one command's parser (help and sub-command actions left out)."""
    exclusive = {
        action.dest: frozenset(a.dest for a in group._group_actions) - {action.dest}
        for group in parser._mutually_exclusive_groups
        for action in group._group_actions
    }
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        positional = not action.option_strings
        found.append(
            Argument(
                flag=None if positional else action.option_strings[0],
                dest=action.dest,
                kind=_kind(action),
                choices=tuple(str(c) for c in action.choices or ()),
                required=action.required or (positional and action.nargs not in ("?", "*")),
                exclusive_with=exclusive.get(action.dest, frozenset()),
            )
        )
    return found


def _kind(action: argparse.Action) -> str:
    if action.nargs == 0:
        return "switch"
    if action.choices:
        return "choice"
    kind = action.type
    name = getattr(kind, "__name__", "")
    if kind is Path:
        return "path"
    if kind is int or name == "whole number":
        return "int"
    if kind is float or name == "number":
        return "float"
    return "word"


def bad_values(argument: Argument) -> tuple[str, ...]:
    """What a case may give ``argument``: wrong in every way its kind allows."""
    if argument.kind == "path":
        return BAD_OUTPUTS if argument.is_output else BAD_INPUTS
    if argument.kind == "choice":
        return argument.choices
    return {"int": BAD_INTS, "float": BAD_FLOATS, "word": BAD_WORDS}.get(argument.kind, ("",))


def good_value(argument: Argument) -> str | None:
    """A value that works for ``argument``, if the workspace has one."""
    if argument.kind == "choice":
        return argument.choices[0]
    if argument.kind == "path" and not argument.is_output:
        return GOOD_INPUTS.get(argument.dest)
    if argument.dest == "target_force":
        return "40000"
    return None


def fuse_values(argument: Argument) -> tuple[str, ...]:
    """Values ``argument`` must refuse at once (empty: it cannot be a fuse)."""
    return FUSE.get(argument.kind, ())


def is_fused(command: tuple[str, ...]) -> bool:
    return command[0] not in OFFLINE


class Workspace:
    """A fresh folder with good and bad files; ``with Workspace() as w:`` also enters it."""

    def __init__(self) -> None:
        self._folder = tempfile.TemporaryDirectory(prefix="boltwatch-bad-")
        self.path = Path(self._folder.name)

    def __enter__(self) -> Workspace:
        self._chdir = contextlib.chdir(self.path)
        self._chdir.__enter__()
        self._make_files()
        return self

    def __exit__(self, *exc: object) -> None:
        self._chdir.__exit__(None, None, None)
        self._folder.cleanup()

    def _make_files(self) -> None:
        here = self.path
        (here / "a-folder").mkdir()
        (here / "a-file.txt").write_text("hello\n")
        (here / "empty.toml").write_bytes(b"")
        (here / "binary.bin").write_bytes(random.Random(14).randbytes(4096))
        (here / "recordings").mkdir()
        (here / "joint.toml").write_text(JOINT_5_2.read_text())
        write_station(
            here,
            replacements={
                'mode = "client"': 'mode = "client"\nconnect_timeout_s = 0.2',
                f'folder = "{here / "recordings"}"': f'folder = "{here / "a-file.txt" / "rec"}"',
            },
        )
        write_trace(here / "good.csv", _trace_rows())
        _write_recording(here / "good.mcap")
        with contextlib.suppress(PermissionError):  # device files need CAP_MKNOD
            os.mknod(here / "full", stat.S_IFCHR | 0o666, os.makedev(1, 7))


def _trace_rows() -> Iterator[tuple[float, float, float, float | None]]:
    for n in range(400):
        yield n * 1e-3, 10.0 + 0.2 * n, 0.1 * n, 1000.0 + 50.0 * n


def _write_recording(path: Path) -> None:
    t0_ns = 1_700_000_000_000_000_000
    with McapSink(path, {}, 3, t0_ns) as sink:
        for n in range(50):
            sample = Sample("st1", 3, n, t0_ns + n * 1_000_000, 10.0 + n, 0.5 * n, 1000.0 + n)
            sink.write(classify("boltwatch/st1/samples", encode(sample), t0_ns + n * 1_000_000))


def command_line(
    command: tuple[str, ...], args: list[Argument], chosen: dict[str, str | None]
) -> list[str]:
    """``command`` with the ``chosen`` values; every other argument that has a good value
    gets it (unless it excludes a chosen one), a required one without gets a bad one."""
    excluded = frozenset().union(*(a.exclusive_with for a in args if a.dest in chosen))
    words = list(command)
    for arg in args:
        if arg.dest in chosen:
            words += arg.render(chosen[arg.dest])
            continue
        if arg.dest in excluded:
            continue
        good = good_value(arg)
        if good is not None and (arg.required or arg.kind != "choice"):
            words += arg.render(good)
        elif arg.required:
            words += arg.render(bad_values(arg)[0])
    return words
