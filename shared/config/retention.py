"""The ``[retention]`` section of a station file: how long the recorder keeps the curves.

The results store keeps every result for ever; the recordings (the curves,
``.mcap`` and the ``.rrd`` beside) grow about 100 KB a run, so a plant
chooses how long to keep them (:mod:`shared.retention`):

- ``keep_days``: a run file last written more than this many days ago goes
  (none, the default: every file is kept for ever: deleting is opted in to);
- ``keep_nok_days``: a file holding a NOK run stays this long instead
  (at least ``keep_days``; none: as long as any other);
- ``max_disk_used_pct``: while the recordings' file system is fuller than
  this (as ``df`` counts it), the oldest files go first until it is not.

A file whose results are not all in the results store is never deleted,
whatever the rule. One recorder serving several station files takes one
``[retention]`` section: files that differ are an error naming both.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from shared.config.loading import StrictModel

#: a day in nanoseconds
DAY_NS = 86_400 * 1_000_000_000


class RetentionSection(StrictModel):
    keep_days: int | None = Field(
        default=None,
        ge=1,
        le=36_500,
        description="a recording last written more than this many days ago is deleted; "
        "none: kept for ever",
    )
    keep_nok_days: int | None = Field(
        default=None,
        ge=1,
        le=36_500,
        description="a recording holding a NOK result is kept this many days instead "
        "(at least keep_days); none: as keep_days",
    )
    max_disk_used_pct: float | None = Field(
        default=None,
        ge=1,
        le=99,
        description="past this % used (as df counts it), the oldest recordings are deleted "
        "until it is not; none: no disk rule",
    )

    @model_validator(mode="after")
    def _consistent(self) -> RetentionSection:
        if self.keep_nok_days is not None:
            if self.keep_days is None:
                raise ValueError(
                    "keep_nok_days needs keep_days (without it every recording is kept "
                    "for ever, NOK or not)"
                )
            if self.keep_nok_days < self.keep_days:
                raise ValueError(
                    f"keep_nok_days ({self.keep_nok_days}) must not be less than keep_days "
                    f"({self.keep_days}): NOK runs are kept longer, not shorter"
                )
        return self

    @property
    def deletes(self) -> bool:
        """Whether any rule deletes anything (the default deletes nothing)."""
        return self.keep_days is not None or self.max_disk_used_pct is not None

    @property
    def keep_ns(self) -> int | None:
        return None if self.keep_days is None else self.keep_days * DAY_NS

    @property
    def keep_nok_ns(self) -> int | None:
        days = self.keep_nok_days if self.keep_nok_days is not None else self.keep_days
        return None if days is None else days * DAY_NS

    def describe(self) -> str:
        """The rules in a few words, e.g. ``curves kept 30 days, NOK 365 days, the disk at
        most 90 % used``."""
        rules = []
        if self.keep_days is not None:
            rules.append(f"curves kept {self.keep_days} days")
            if self.keep_nok_days is not None:
                rules.append(f"NOK {self.keep_nok_days} days")
        if self.max_disk_used_pct is not None:
            rules.append(f"the disk at most {self.max_disk_used_pct:g} % used")
        return ", ".join(rules) or "every curve kept for ever"
