"""The two reference pages written from the code: the command line and the channel table.

``docs/reference/cli.md`` is written from ``boltwatch``'s argparse parser
(:func:`services.cli.main.build_parser`), ``docs/reference/channels.md`` from
the channel table (:data:`shared.contract.channels.CHANNELS`) and the message
dataclasses it names. Neither is edited by hand; after changing an option or
a channel, write them again::

    .venv/bin/python -m services.cli.reference_pages          # write both
    .venv/bin/python -m services.cli.reference_pages --check  # exit 1 if either differs

``make docs`` writes them before it builds the site, and a test of the suite
fails when a committed page differs from what this module writes now.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import inspect
import io
import re
import sys
import textwrap
import tokenize
import typing
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from services.cli import main as cli_main
from shared.contract import channels as channel_table
from shared.contract import keys, message_fields

#: the pages, relative to the docs folder
CLI_PAGE = Path("reference") / "cli.md"
CHANNELS_PAGE = Path("reference") / "channels.md"

GENERATED_NOTE = (
    "<!-- Written by `python -m services.cli.reference_pages` from {source}; "
    "do not edit by hand. -->"
)
#: wide enough that no usage line of ours wraps in the middle of an option
USAGE_WIDTH = 100


# -- text ------------------------------------------------------------------------------------

_ROLE = re.compile(r":(?:class|func|meth|attr|data|mod|exc):`~?([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")


def markdown_of(text: str) -> str:
    """A docstring's reST made Markdown: ``code`` and :role:`name` become `code`."""
    text = _ROLE.sub(lambda match: f"`{match.group(1).lstrip('.')}`", text)
    text = _LITERAL.sub(r"`\1`", text)
    return text.replace("::\n", ":\n")


def cell(text: str) -> str:
    """Text that fits in one cell of a Markdown table: one line, ``|`` escaped outside code
    (inside a code span the table reads it as text, and an escape would show)."""
    parts = " ".join(text.split()).split("`")
    return "`".join(
        part if index % 2 else part.replace("|", "\\|") for index, part in enumerate(parts)
    )


def paragraphs(text: str) -> str:
    """A docstring's paragraphs and lists, each item on one line, reST made Markdown."""
    blocks = []
    for block in inspect.cleandoc(text).split("\n\n"):
        items: list[str] = []
        for line in block.splitlines():
            if line.startswith("- ") or not items:
                items.append(line.strip())
            else:
                items[-1] += " " + line.strip()
        blocks.append("\n".join(" ".join(item.split()) for item in items))
    return markdown_of("\n\n".join(block for block in blocks if block))


# -- the command line ------------------------------------------------------------------------


def _subcommands(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            yield from action.choices.values()


def _one_line_helps(parser: argparse.ArgumentParser) -> dict[str, str]:
    """Subcommand prog -> its one-line help (what ``boltwatch --help`` lists)."""
    helps = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                helps[f"{parser.prog} {choice.dest}"] = choice.help or ""
    return helps


def _usage(parser: argparse.ArgumentParser) -> str:
    formatter = argparse.HelpFormatter(parser.prog, width=USAGE_WIDTH)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
    return formatter.format_help().strip()


def _argument_name(action: argparse.Action) -> str:
    if action.option_strings:
        names = ", ".join(action.option_strings)
        if action.nargs == 0:
            return names
        metavar = action.metavar or action.dest.upper()
        if isinstance(metavar, tuple):
            metavar = " ".join(metavar)
        several = " ..." if action.nargs in ("+", "*") else ""
        return f"{names} {metavar}{several}"
    return str(action.metavar or action.dest)


def _argument_help(action: argparse.Action, prog: str) -> str:
    formatter = argparse.HelpFormatter(prog)
    text = formatter._expand_help(action) if action.help else ""
    if action.choices is not None and not isinstance(action, argparse._SubParsersAction):
        choices = ", ".join(str(choice) for choice in action.choices)
        if choices not in text:
            text = f"{text} (one of: {choices})" if text else f"one of: {choices}"
    default = action.default
    shown = default not in (None, False, argparse.SUPPRESS, "", [])
    if shown and action.nargs != 0 and "default" not in text:
        if isinstance(default, list | tuple):
            default = " ".join(str(item) for item in default)
        text += f" (default: {default})"
    return cell(text)


def _arguments_table(parser: argparse.ArgumentParser) -> list[str]:
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        rows.append(f"| `{_argument_name(action)}` | {_argument_help(action, parser.prog)} |")
    if not rows:
        return []
    return ["| argument | what it is |", "|---|---|", *rows, ""]


def _command_section(parser: argparse.ArgumentParser, level: int) -> list[str]:
    lines = [f"{'#' * level} `{parser.prog}`", ""]
    if parser.description:
        lines += [cell(parser.description), ""]
    lines += ["```", _usage(parser), "```", ""]
    lines += _arguments_table(parser)
    for sub in _subcommands(parser):
        lines += _command_section(sub, level + 1)
    return lines


def cli_page() -> str:
    """``docs/reference/cli.md``: every command, its usage and its arguments."""
    parser = cli_main.build_parser()
    subs = list(_subcommands(parser))
    helps = _one_line_helps(parser)
    lines = [
        GENERATED_NOTE.format(source="the parser of `services/cli/main.py`"),
        "",
        "# Command line",
        "",
        "One console script, `boltwatch`, with one subcommand per task. This page is "
        "written from its parser: what `boltwatch COMMAND --help` says, every option "
        "with its default.",
        "",
        "```",
        cli_main.DESCRIPTION.strip(),
        "```",
        "",
        "## How a command ends",
        "",
        paragraphs(cli_main.__doc__ or "").split("\n\n", 1)[1],
        "",
        "## Commands",
        "",
        "| command | what it does |",
        "|---|---|",
        *[f"| [`{sub.prog}`](#{_anchor(sub.prog)}) | {cell(helps[sub.prog])} |" for sub in subs],
        "",
    ]
    for sub in subs:
        lines += _command_section(sub, 2)
    return "\n".join(lines).rstrip() + "\n"


def _anchor(title: str) -> str:
    """The id MkDocs gives a heading of ``title`` (in backquotes)."""
    return re.sub(r"[^\w\- ]", "", title.lower()).strip().replace(" ", "-")


# -- the channel table -----------------------------------------------------------------------


def _source_comments(source: str) -> dict[int, str]:
    comments = {}
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            text = token.string.lstrip("#").lstrip(":").strip()
            if not text.startswith(("noqa", "type:")):
                comments[token.start[0]] = text
    return comments


def field_notes(cls: type) -> dict[str, tuple[str, str]]:
    """Field name -> (its annotation as written, the comments beside and above it)."""
    source = textwrap.dedent(inspect.getsource(cls))
    lines = source.splitlines()
    comments = _source_comments(source)
    classdef = ast.parse(source).body[0]
    assert isinstance(classdef, ast.ClassDef)
    notes = {}
    for node in classdef.body:
        if not (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)):
            continue
        above: list[str] = []
        number = node.lineno - 1
        while number >= 1 and lines[number - 1].lstrip().startswith("#"):
            above.insert(0, comments.get(number, ""))
            number -= 1
        last = node.end_lineno or node.lineno
        beside = [comments.get(number, "") for number in range(node.lineno, last + 1)]
        annotation = ast.get_source_segment(source, node.annotation) or ""
        notes[node.target.id] = (annotation, " ".join(part for part in above + beside if part))
    return notes


def _dataclasses_in(annotation: Any) -> Iterator[type]:
    if dataclasses.is_dataclass(annotation) and isinstance(annotation, type):
        yield annotation
    for argument in typing.get_args(annotation):
        yield from _dataclasses_in(argument)


def _literal_values(cls: type, name: str) -> str:
    """``'idle', 'running', ...`` where a field's annotation names a Literal alias."""
    module = sys.modules[cls.__module__]
    alias = getattr(module, name.split(" | ", maxsplit=1)[0], None)
    if typing.get_origin(alias) is typing.Literal:
        return ", ".join(f"`{value}`" for value in typing.get_args(alias))
    return ""


def _fields_table(cls: type) -> list[str]:
    notes = field_notes(cls)
    rows = ["| field | type | meaning |", "|---|---|---|"]
    for item in dataclasses.fields(cls):
        if item.name.startswith("_"):
            continue
        annotation, note = notes.get(item.name, (str(item.type), ""))
        values = _literal_values(cls, annotation)
        if values:
            note = f"{note}; one of {values}" if note else f"one of {values}"
        if item.default is not dataclasses.MISSING:
            note = f"{note} (default {item.default!r})" if note else f"default {item.default!r}"
        elif item.default_factory is not dataclasses.MISSING:
            note = f"{note} (default empty)" if note else "default empty"
        rows.append(f"| `{item.name}` | {cell(f'`{annotation}`')} | {cell(markdown_of(note))} |")
    return [*rows, ""]


def _nested_types(messages: Sequence[type]) -> list[type]:
    """The dataclasses the messages hold (a step, a prediction), each once, in order seen."""
    seen: list[type] = []
    queue = list(messages)
    while queue:
        cls = queue.pop(0)
        hints = typing.get_type_hints(cls, include_extras=False)
        for item in dataclasses.fields(cls):
            for nested in _dataclasses_in(hints[item.name]):
                if nested not in messages and nested not in seen:
                    seen.append(nested)
                    queue.append(nested)
    return seen


def _qos_text(channel: channel_table.Channel[Any]) -> str:
    priority = "REAL_TIME" if channel.qos.real_time else "DATA"
    express = "express" if channel.qos.express else "batched by zenoh"
    return f"{priority}, BLOCK, {express}"


def _alias_rows() -> list[str]:
    """The field types of ``message_fields`` with their comment and bounds."""
    source = inspect.getsource(message_fields)
    comments = _source_comments(source)
    rows = ["| type | what it holds | bounds |", "|---|---|---|"]
    for node in ast.parse(source).body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1):
            continue
        target = node.targets[0]
        if not isinstance(target, ast.Name):
            continue
        alias = getattr(message_fields, target.id)
        if typing.get_origin(alias) is not typing.Annotated:
            continue
        base, *metadata = typing.get_args(alias)
        bounds = "; ".join(_bound_text(item) for item in metadata)
        meaning = comments.get(node.lineno - 1, "")
        what = f"{cell(markdown_of(meaning))} ({base.__name__})"
        rows.append(f"| `{target.id}` | {what} | {bounds} |")
    return [*rows, ""]


def _bound_text(metadata: Any) -> str:
    if isinstance(metadata, message_fields.NumberRange):
        if metadata.high == message_fields.FLOAT_MAX:
            text = "any finite number"
        else:
            text = f"{_number(metadata.low)} to {_number(metadata.high)}"
        return f"{text}, NaN and infinities too" if metadata.nan_ok else text
    if isinstance(metadata, message_fields.TextRange):
        text = f"at most {metadata.max_chars} characters"
        if metadata.pattern is not None:
            text += f", matching `{metadata.pattern.pattern}`"
        return text
    return cell(repr(metadata))


def _number(value: float) -> str:
    if value == message_fields.INT64_MAX:
        return "2⁶³ − 1"
    if value == message_fields.INT64_MIN:
        return "−2⁶³"
    return f"{value:g}"


def channels_page() -> str:
    """``docs/reference/channels.md``: every channel of the table, its message and fields."""
    table = channel_table.CHANNELS
    messages = [channel.message_type for channel in table]
    lines = [
        GENERATED_NOTE.format(source="`shared/contract/channels.py` and the message dataclasses"),
        "",
        "# Channels",
        "",
        f"Every channel is a zenoh key below a station, `{keys.ROOT}/<station>/<topic>`, "
        f"carrying one message type as one JSON object (encoding `{channel_table.ENCODING}`), "
        "with the JSON schema the codec derives from the dataclass: the same schema goes "
        "into each MCAP channel and the live Foxglove view, under the schema name "
        "`boltwatch.<Type>`. Every channel is put with congestion control BLOCK.",
        "",
        "| topic | key | message | schema | publisher | also put by | zenoh QoS |",
        "|---|---|---|---|---|---|---|",
    ]
    for channel in table:
        also = ", ".join(channel.also_by) or "-"
        name = channel.message_type.__name__
        lines.append(
            f"| `{channel.topic}` | `{channel.key('<station>')}` | [`{name}`](#{name.lower()}) "
            f"| `{channel.schema_name}` | {channel.publisher} | {also} | {_qos_text(channel)} |"
        )
    lines += [
        "",
        f"Not channels (`shared/contract/keys.py`): `{keys.health_key('<station>', '<service>')}`, "
        "the liveliness token of each service, and "
        f"`{keys.station_key('<station>', keys.WEAR)}`, the recorder's queryable of the wear "
        "ledger.",
        "",
        "## How a channel is put",
        "",
        paragraphs(channel_table.Qos.__doc__ or ""),
        "",
        "A station's samples go toward the line on one of the two sample channels: "
        "`samples` where a line predictor decides on them (`[predictor] placement = "
        '"line"`), `sample_batches` otherwise. Why each channel is put as it is: '
        "[the design, the line's channels](../explanation/design.md#the-lines-channels).",
        "",
        "## Field types",
        "",
        paragraphs((message_fields.__doc__ or "").split("\n\n")[0]),
        "",
        *_alias_rows(),
        "## Messages",
        "",
    ]
    for cls in messages:
        lines += [f"### {cls.__name__}", "", paragraphs(cls.__doc__ or ""), ""]
        lines += _fields_table(cls)
    nested = _nested_types(messages)
    if nested:
        lines += ["## Types inside messages", ""]
        for cls in nested:
            lines += [f"### {cls.__name__}", "", paragraphs(cls.__doc__ or ""), ""]
            lines += _fields_table(cls)
    return "\n".join(lines).rstrip() + "\n"


# -- writing and checking --------------------------------------------------------------------

PAGES = {CLI_PAGE: cli_page, CHANNELS_PAGE: channels_page}


def stale_pages(docs: Path) -> list[Path]:
    """The generated pages under ``docs`` that differ from what this module writes now."""
    return [
        docs / page
        for page, render in PAGES.items()
        if not (docs / page).is_file() or (docs / page).read_text(encoding="utf-8") != render()
    ]


def write_pages(docs: Path) -> list[Path]:
    """Write every generated page under ``docs``; the pages that changed."""
    changed = stale_pages(docs)
    for page, render in PAGES.items():
        (docs / page).parent.mkdir(parents=True, exist_ok=True)
        (docs / page).write_text(render(), encoding="utf-8")
    return changed


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m services.cli.reference_pages",
        description="Write docs/reference/cli.md and channels.md from the code.",
    )
    parser.add_argument("--docs", type=Path, default=Path("docs"), help="the docs folder")
    parser.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 if a page differs"
    )
    args = parser.parse_args(argv)
    if args.check:
        stale = stale_pages(args.docs)
        for path in stale:
            print(f"{path}: differs from the code; run python -m services.cli.reference_pages")
        return 1 if stale else 0
    for path in write_pages(args.docs):
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
