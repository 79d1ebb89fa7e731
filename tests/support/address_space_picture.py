"""A picture of an OPC UA address space as a generic browser shows it: :func:`tree_page`
draws the nodes node-opcua's client browsed (``opcua_browse_tree.js``) as a browser's
tree (node class, browse name, type definition, data type, value), :func:`screenshot`
photographs the page in Debian's chromium (:mod:`.chromium`). The picture of
``docs/how-to/opcua.md`` is made so (``BOLTWATCH_DOCS_IMAGES=1``, the OPC UA system test).
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tests.support.chromium import CHROMIUM, CHROMIUM_ARGS

#: each node class's mark and colour, as browsers draw them
_CLASSES = {
    "Object": ("O", "#2f6db5"),
    "Variable": ("V", "#2e8b57"),
    "Method": ("M", "#c0602b"),
    "ObjectType": ("OT", "#6a5acd"),
    "VariableType": ("VT", "#6a5acd"),
}
#: a value's characters shown (longer ones end in an ellipsis)
_VALUE_CHARS = 48
_STYLE = """
body { font: 13px "DejaVu Sans", sans-serif; margin: 0; background: #f3f3f3; }
caption { background: #3b4b5c; color: #fff; padding: 6px 10px; font-weight: bold;
          text-align: left; }
table { border-collapse: collapse; width: 100%; background: #fff; }
th { text-align: left; background: #e4e4e4; padding: 3px 8px; border-bottom: 1px solid #bbb; }
td { padding: 1px 8px; white-space: nowrap; border-bottom: 1px solid #f0f0f0; }
td.type, td.value { color: #555; }
.mark { display: inline-block; width: 20px; font-size: 10px; text-align: center;
        color: #fff; border-radius: 3px; margin-right: 4px; }
.expander { display: inline-block; width: 12px; color: #777; }
"""


def tree_page(nodes: Sequence[dict[str, Any]], title: str) -> str:
    """The page of ``nodes`` (in browse order, each with its depth), under ``title``."""
    rows = []
    for index, node in enumerate(nodes):
        expanded = index + 1 < len(nodes) and nodes[index + 1]["depth"] > node["depth"]
        expander = "▾" if expanded else ("▸" if node["children"] else "")
        mark, colour = _CLASSES.get(node["nodeClass"], ("?", "#888"))
        value = "" if node["value"] is None else str(node["value"])
        if len(value) > _VALUE_CHARS:
            value = value[: _VALUE_CHARS - 1] + "…"
        rows.append(
            "<tr><td>"
            f'<span style="padding-left: {18 * node["depth"]}px"></span>'
            f'<span class="expander">{expander}</span>'
            f'<span class="mark" style="background: {colour}">{mark}</span>'
            f"{html.escape(node['name'])}</td>"
            f'<td class="type">{html.escape(node["type"] or "")}</td>'
            f'<td class="type">{html.escape(node["dataType"] or "")}</td>'
            f'<td class="value">{html.escape(value)}</td></tr>'
        )
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><style>{_STYLE}</style></head>"
        f"<body><table><caption>{html.escape(title)}</caption>"
        "<tr><th>Address space</th><th>Type definition</th><th>Data type</th><th>Value</th></tr>"
        + "".join(rows)
        + "</table></body></html>"
    )


def screenshot(page_html: str, path: Path, width_px: int = 1100) -> None:
    """``page_html`` photographed whole in a headless chromium, as a PNG at ``path``."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": width_px, "height": 600})
        page.set_content(page_html)
        page.screenshot(path=str(path), full_page=True)
        browser.close()
