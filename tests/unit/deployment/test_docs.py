"""The documentation: it builds without a warning, and cannot drift from the code.

- ``docs/reference/cli.md`` and ``channels.md`` are what
  :mod:`services.cli.reference_pages` writes from the parser and the channel
  table now;
- ``mkdocs build --strict`` passes (a warning fails it: a broken link to a
  page or an anchor, a page left out of the nav, an absolute link);
- every path of the tree that ``docs/`` or the README names exists (a test
  path in the faults table, a module a page points to);
- every key of a station, controller station or joint file is in the
  configuration page.
"""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
import typing
from collections.abc import Iterator
from pathlib import Path

import pydantic
import pytest

from services.cli.reference_pages import PAGES, stale_pages
from shared.config import ControllerStationConfig, JointConfig, StationConfig
from tests.support.paths import REPO

DOCS = REPO / "docs"
#: a path of the tree in a page: tests/..., services/..., shared/..., config/...
TREE_PATH = re.compile(r"(?<![\w./-])((?:tests|services|shared|config)/[\w./-]*[\w/])")


def pages() -> list[Path]:
    return [*sorted(DOCS.rglob("*.md")), REPO / "README.md"]


def test_the_generated_reference_pages_are_what_the_code_writes_now() -> None:
    stale = stale_pages(DOCS)
    assert not stale, (
        f"{', '.join(str(path.relative_to(REPO)) for path in stale)} differ from the code: "
        "run .venv/bin/python -m services.cli.reference_pages and commit the pages"
    )
    assert set(PAGES) == {Path("reference/cli.md"), Path("reference/channels.md")}


def test_the_site_builds_with_no_warning(tmp_path: Path) -> None:
    if importlib.util.find_spec("mkdocs") is None:
        pytest.skip(
            "mkdocs is not installed (it comes with the dev extra: pip install -e '.[dev]')"
        )
    environment = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # Material's notice, not ours
    built = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env=environment,
    )
    log = built.stdout + built.stderr
    assert built.returncode == 0, log
    assert "WARNING" not in log, log
    assert (tmp_path / "site" / "reference" / "faults.html").is_file()


def named_paths(text: str) -> Iterator[str]:
    """The paths of the tree a page names; placeholders (``<station>``, ``*``) left out."""
    for match in TREE_PATH.finditer(text):
        path = match.group(1).split("::")[0].rstrip(".")
        end = match.end(1)
        if text[end : end + 1] in ("<", "*", "{") or "K." in path:
            continue  # a pattern: stationK.toml, <room>, *.toml
        yield path


def test_every_path_the_docs_name_exists() -> None:
    missing = [
        f"{page.relative_to(REPO)}: {path}"
        for page in pages()
        for path in named_paths(page.read_text(encoding="utf-8"))
        if not (REPO / path).exists()
    ]
    assert not missing, "paths named in the docs that are not in the tree:\n" + "\n".join(missing)


def test_every_test_path_of_the_faults_table_exists() -> None:
    table = (DOCS / "reference" / "faults.md").read_text(encoding="utf-8")
    tests = {path for path in named_paths(table) if path.startswith("tests/")}
    assert len(tests) > 50
    assert all((REPO / path).is_file() for path in tests)


def keys(model: type[pydantic.BaseModel], prefix: str = "") -> Iterator[str]:
    """Every leaf key of a configuration model, dotted (``programs[].joint``)."""
    for name, field in model.model_fields.items():
        annotation = field.annotation
        inner = typing.get_args(annotation) or (annotation,)
        models = [t for t in inner if isinstance(t, type) and issubclass(t, pydantic.BaseModel)]
        if models:
            separator = "[]." if typing.get_origin(annotation) is list else "."
            yield from keys(models[0], f"{prefix}{name}{separator}")
        else:
            yield f"{prefix}{name}"


@pytest.mark.parametrize("model", [StationConfig, ControllerStationConfig, JointConfig])
def test_the_configuration_page_names_every_key(model: type[pydantic.BaseModel]) -> None:
    page = (DOCS / "reference" / "configuration.md").read_text(encoding="utf-8")
    spans = re.findall(r"`([^`\n]+)`", page)  # code spans of one line: `key`, `section.key`
    named = {word for span in spans for word in re.split(r"\W+", span)}
    missing = [key for key in keys(model) if key.rsplit(".", 1)[-1] not in named]
    assert not missing, (
        f"keys of {model.__name__} not in docs/reference/configuration.md: {missing}"
    )
