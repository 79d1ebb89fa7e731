"""No traceback anywhere: every ``boltwatch`` command, given bad paths and bad values, ends
with one line on stderr and exit status 2 (or succeeds, exit 0).

The commands and their arguments come from the parser (:mod:`tests.support.bad_arguments`),
so a new command or option is driven here without a change. Every case runs in-process
through ``services.cli.main.main``: an exception that escapes it fails the test with the
command line that raised it. Cases that need a real process (a pipe closed by its reader,
a file size limit) are in ``test_closed_output.py``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from services.cli.main import main
from tests.support.bad_arguments import (
    LOG_LINE,
    Argument,
    Workspace,
    arguments,
    bad_values,
    command_line,
    commands,
    fuse_values,
    good_value,
    is_fused,
)

COMMANDS = commands()


@dataclass(frozen=True)
class Outcome:
    argv: list[str]
    status: int
    out: str
    err: str


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> Outcome:
    """``boltwatch ARGV`` in-process; an exception other than argparse's exit fails the test."""
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    try:
        status = main(argv)
    except SystemExit as exit_:  # argparse: a usage error (2), or --help (0)
        status = int(exit_.code or 0)
    except Exception as err:
        raise AssertionError(f"boltwatch {shown(argv)} raised {type(err).__name__}") from err
    finally:
        root.handlers[:] = handlers
        root.setLevel(level)
    captured = capsys.readouterr()
    return Outcome(argv, status, captured.out, captured.err)


def shown(argv: list[str]) -> str:
    return " ".join(repr(word) if not word or " " in word else word[:60] for word in argv)


def check(outcome: Outcome) -> None:
    """Exit 0 or 2; on stderr only one-line messages (``boltwatch ...``), a service's log
    lines or argparse's usage; a failure ends with a ``boltwatch ...`` line."""
    where = f"boltwatch {shown(outcome.argv)}\n--- stderr:\n{outcome.err}"
    assert outcome.status in (0, 2), f"exit status {outcome.status}: {where}"
    assert "Traceback" not in outcome.err, where
    lines = [line for line in outcome.err.splitlines() if line.strip()]
    usage = any(line.startswith("usage:") for line in lines)
    for line in lines:
        one_line = line.startswith("boltwatch ") or LOG_LINE.match(line)
        assert one_line or usage, f"not a one-line message: {line!r}\n{where}"
    if outcome.status == 2:
        assert lines and lines[-1].startswith("boltwatch "), where


def table() -> list[tuple[tuple[str, ...], Argument]]:
    return [
        (command, argument)
        for command, parser in COMMANDS.items()
        for argument in arguments(parser)
        if argument.kind not in ("switch",)
    ]


@pytest.mark.parametrize(
    ("command", "argument"),
    table(),
    ids=[f"{' '.join(c)} {a.flag or a.dest}" for c, a in table()],
)
def test_each_bad_value_of_each_argument_ends_in_one_line(
    command: tuple[str, ...], argument: Argument, capsys: pytest.CaptureFixture[str]
) -> None:
    """One argument at a time gets every bad value of its kind, the others good ones. A
    command that could block gets only values it must refuse at once (its fuse); an argument
    without such values is tried with another argument fused."""
    args = arguments(COMMANDS[command])
    values = bad_values(argument)
    fuse: dict[str, str | None] = {}
    if is_fused(command):
        values = fuse_values(argument)
        if not values:
            values = (good_value(argument) or bad_values(argument)[0],)
            fuse = _some_fuse(args, argument)
    for value in values:
        with Workspace():
            check(run_cli(command_line(command, args, {**fuse, argument.dest: value}), capsys))


def _some_fuse(args: list[Argument], besides: Argument) -> dict[str, str | None]:
    for other in args:
        if other is not besides and other.dest not in besides.exclusive_with:
            values = fuse_values(other)
            if values:
                return {other.dest: values[0]}
    raise AssertionError(f"no argument to fuse besides {besides.dest}")


@st.composite
def command_lines(draw: st.DrawFn, command: tuple[str, ...]) -> list[str]:
    """Any mix of good, bad and left-out values for the arguments of ``command``; a command
    that could block gets one argument that must be refused at once."""
    args = arguments(COMMANDS[command])
    chosen: dict[str, str | None] = {}
    for arg in args:
        good = good_value(arg)
        options = [*bad_values(arg), *([good] if good is not None else [])]
        if arg.kind == "switch":
            options = ["on"]
        if arg.required or draw(st.booleans()):
            chosen[arg.dest] = draw(st.sampled_from(options))
    if is_fused(command):
        fusable = [arg for arg in args if fuse_values(arg)]
        assert fusable, f"boltwatch {' '.join(command)} has no argument that can be a fuse"
        fused = draw(st.sampled_from(fusable))
        chosen[fused.dest] = draw(st.sampled_from(fuse_values(fused)))
        for dest in fused.exclusive_with:
            chosen.pop(dest, None)
    return command_line(command, args, chosen)


@pytest.mark.parametrize("command", list(COMMANDS), ids=[" ".join(c) for c in COMMANDS])
@settings(
    max_examples=8,  # per command: ~130 command lines in all, a few seconds
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],  # capsys: read per example
)
@given(data=st.data())
def test_any_mix_of_bad_arguments_ends_in_one_line(
    command: tuple[str, ...], data: st.DataObject, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = data.draw(command_lines(command))
    with Workspace():
        check(run_cli(argv, capsys))


def test_every_command_is_driven() -> None:
    """The parser is walked: the commands named here are all found (a new one is driven too)."""
    names = {" ".join(command) for command in COMMANDS}
    expected = {
        "up", "health", "predict", "simulate", "import", "model", "recover", "export",
        "inspect", "wear", "status",
        *(f"serve {s}" for s in ("rig", "acquisition", "predictor", "recorder", "router")),
    }  # fmt: skip
    assert expected <= names
