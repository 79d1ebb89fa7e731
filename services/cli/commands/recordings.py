"""``boltwatch recordings``: the recordings folder's upkeep.

::

    boltwatch recordings prune [--config FILE ...] [--dry-run]

``prune`` applies the station files' ``[retention]`` now, as the line's
recorder does every few minutes, with the same code
(:mod:`shared.retention`): one line per file that goes (``--dry-run``: would
go) and per file kept past its time, then per reason how many files, bytes,
and written from when to when. A file whose results are not all in the
results store is never deleted, nor the newest file of a station or one
written in the last hour (a recorder may have it open). Station files
sharing a recordings folder must agree on ``[retention]`` and the store. No
results store there: one line, exit status 2 (``boltwatch results rebuild``
makes one); a file that could not be deleted: one line each on stderr, exit
status 2. A recordings folder that is a symlink loop: one line, exit status 2; a
symlink loop in it is named on stderr and never touched.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import TYPE_CHECKING

from services.cli.command_options import add_station_file_option

if TYPE_CHECKING:
    from shared.retention import Decision, RetentionPlan, RetentionScope

NAME = "recordings"
HELP = "the recordings' upkeep: prune deletes what the station file's [retention] lets go"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    prune_help = (
        "delete the recordings the station files' [retention] lets go now (--dry-run: say "
        "which), as the line's recorder does every 10 minutes; never one whose results are "
        "not in the results store"
    )
    prune = actions.add_parser("prune", help=prune_help, description=prune_help)
    add_station_file_option(
        prune, "station file(s): their recordings, [retention] and store", several=True
    )
    prune.add_argument(
        "--dry-run",
        action="store_true",
        help="delete nothing: list the files that would go, and why, and those kept",
    )
    prune.set_defaults(command_label=f"{NAME} prune")


def run(args: argparse.Namespace) -> int:
    from shared.config import load_any_station
    from shared.retention import retention_scopes

    scopes = retention_scopes([load_any_station(path) for path in args.config])
    failed = 0
    for scope in scopes:
        failed += _prune(scope, args.dry_run)
    return 2 if failed else 0


def _prune(scope: RetentionScope, dry_run: bool) -> int:
    """Prune one folder, saying what goes; the number of files that could not be deleted."""
    from shared.recordings import check_walkable
    from shared.results import ResultsStore
    from shared.retention import FileResultsCache, delete_planned, plan_pass

    policy = scope.policy
    check_walkable(scope.folder)
    print(f"recordings of {scope.folder} ({', '.join(scope.stations)}): {policy.describe()}")
    if not policy.deletes:
        print("nothing deleted: [retention] keep_days or max_disk_used_pct in the station file")
        return 0
    with ResultsStore(
        scope.target, create=False, application="boltwatch recordings prune"
    ) as store:
        plan = plan_pass(scope, store, FileResultsCache(), time.time_ns())
    for line in plan.skipped:
        print(f"boltwatch recordings prune: warning: {line}; skipped", file=sys.stderr)
    deleted, failed = plan.deletions, []
    if not dry_run:
        outcome = delete_planned(plan)
        deleted, failed = outcome.deleted, outcome.failed
    for decision, why in failed:
        print(
            f"boltwatch recordings prune: {decision.file.path}: not deleted: {why}", file=sys.stderr
        )
    for decision in deleted:
        print(_file_line("would delete" if dry_run else "deleted", decision))
    for decision in plan.kept:
        print(_file_line("kept", decision))
    for line in _summary(plan, deleted, scope, dry_run):
        print(line)
    return len(failed)


def _file_line(verb: str, decision: Decision) -> str:
    from shared.retention import bytes_text, utc_minute

    recording = decision.file
    return (
        f"{verb}  {recording.path}  {bytes_text(recording.size_bytes)}  "
        f"written {utc_minute(recording.modified_ns)} UTC  ({decision.reason})"
    )


def _summary(
    plan: RetentionPlan, deleted: list[Decision], scope: RetentionScope, dry_run: bool
) -> list[str]:
    from shared.retention import bytes_text, deleted_tallies, kept_tallies, reason_text

    lines = []
    usage = plan.usage
    if usage is not None:
        lines.append(f"the disk: {usage.used_pct:.1f} % used")
    gone = deleted_tallies(deleted)
    if not gone:
        lines.append("nothing to delete" if dry_run else "nothing deleted")
    for reason, tally in gone.items():
        if reason:
            lines.append(f"  {tally.text()}: {reason_text(reason, scope.policy, usage)}")
        else:
            lines.append(f"{'would delete' if dry_run else 'deleted'} {tally.text()}:")
    for reason, tally in kept_tallies(plan.kept).items():
        if reason:
            lines.append(f"  {tally.text()}: {reason_text(reason, scope.policy)}")
        else:
            lines.append("kept past their time:")
    if plan.disk_short_bytes:
        lines.append(
            f"the disk stays above max_disk_used_pct ({scope.policy.max_disk_used_pct:g} %): "
            f"{bytes_text(plan.disk_short_bytes)} more would have to go, and nothing else may"
        )
    return lines
