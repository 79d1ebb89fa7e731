"""Debian's chromium, driven by playwright (never ``playwright install``): where it is and
how it is started. ``.ci/run`` installs it as root when missing; tests that need it skip
with the reason where it cannot be had."""

from __future__ import annotations

from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
#: why a test that needs it skips
MISSING = f"{CHROMIUM} is missing (.ci/run installs Debian's chromium as root)"
