"""Links from a run's view to the viewers a plant already has: Rerun's web viewer and
Foxglove, where they are reachable (the line server may be offline: none by default).

A viewer is named by a URL template (an option of ``serve dashboard``) with ``{url}``
where the address of the run's file goes, URL-encoded by the page, e.g.::

    --rerun-viewer 'https://app.rerun.io/version/0.41.0/?url={url}'
    --foxglove 'https://app.foxglove.dev/~/view?ds=remote-file&ds.url={url}'

The viewer then fetches the file from the page's server, from its own origin, so the
file downloads answer that origin's requests (CORS): ``Access-Control-Allow-Origin``
naming it, never ``*``: another web page a browser on the plant's network opens cannot
read the recordings through it.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from urllib.parse import urlsplit

PLACE = "{url}"


def viewer_template(text: str) -> str:
    """A viewer's URL template (argparse's type): http(s), a host, ``{url}`` once."""
    parts = urlsplit(text)
    if parts.scheme not in ("http", "https") or not parts.netloc or text.count(PLACE) != 1:
        raise argparse.ArgumentTypeError(
            f"expected an http(s) URL with {PLACE} once where the file's address goes, "
            f"e.g. 'https://viewer.example/?url={PLACE}' (got {text!r})"
        )
    if PLACE in parts.netloc or PLACE in parts.scheme:
        raise argparse.ArgumentTypeError(f"{PLACE} goes after the viewer's host (got {text!r})")
    return text


def origin_of(template: str) -> str:
    """The origin a viewer's page runs on (what its browser sends as ``Origin``)."""
    parts = urlsplit(template)
    return f"{parts.scheme}://{parts.netloc}".lower()


@dataclass(frozen=True, slots=True)
class ViewerLinks:
    """The viewers the page links a run to (None: no link)."""

    rerun: str | None = None
    foxglove: str | None = None
    origins: frozenset[str] = field(init=False)

    def __post_init__(self) -> None:
        templates = [t for t in (self.rerun, self.foxglove) if t is not None]
        object.__setattr__(self, "origins", frozenset(origin_of(t) for t in templates))

    def as_dict(self) -> dict[str, str | None]:
        return {"rerun": self.rerun, "foxglove": self.foxglove}

    def allows(self, origin: str | None) -> bool:
        """Whether a request from ``origin`` (its ``Origin`` header) is a viewer's."""
        return origin is not None and origin.lower() in self.origins
