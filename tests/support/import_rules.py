"""``make lint``'s check of the tests' own layout: no test module imports another.

A helper two test modules need lives in ``tests/support/``; a test module
(``test_*.py``) or a ``conftest.py`` is never imported by another module. Run as
``python -m tests.support.import_rules``: one line per import that breaks the
rule, exit status 1 when there is one.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

from tests.support.paths import REPO


def test_module_imports(tests: Path) -> list[str]:
    """``file:line: imports test module`` for each import of a test module or conftest."""
    found = []
    for path in sorted(tests.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.ImportFrom) and node.module):
                continue
            names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
            for name in names:
                last = name.rsplit(".", 1)[-1]
                first = name.split(".", 1)[0]
                if (name.startswith("tests.") or first.startswith("test_")) and (
                    last.startswith("test_") or last == "conftest"
                ):
                    where = path.relative_to(REPO)
                    found.append(f"{where}:{node.lineno}: imports {name} (a test module)")
                    break
    return found


def main() -> int:
    found = test_module_imports(REPO / "tests")
    for line in found:
        print(line)
    if found:
        print("move what they share into tests/support/", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
