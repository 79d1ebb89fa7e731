"""Check and recover a Rerun ``.rrd`` that a killed recorder left without its footer.

What this Rerun (0.41) says about a cut file, as measured: ``rerun rrd verify``
exits 1 with "Missing RRD footer / no RRD manifests"; the Python
``RrdReader`` raises ("Message payload ... exceeds file size") before it
yields a chunk, so nothing is readable through it. ``rerun rrd merge
--continue-on-error`` copies every complete chunk into a new file that
``rrd verify`` accepts. A file cut inside its first frame passes ``rrd
verify`` ("0 files verified without error", exit 0): counted as empty here.
:func:`recover_rrd` does exactly that, with the
``rerun`` CLI of the installed wheel, and counts what came back. The
damaged file is never changed.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from shared.recordings.mcap import remove_unfinished
from shared.recordings.rerun.rerun_blueprint import TORQUE
from shared.errors import InputError

SAMPLES_ENTITY = f"/{TORQUE}"  # one row per recorded sample
_TIMEOUT_S = 120


@dataclass(frozen=True, slots=True)
class RrdCheck:
    path: Path
    ok: bool
    problem: str | None  # what ``rerun rrd verify`` said when not ok


@dataclass(frozen=True, slots=True)
class RrdRecovery:
    source: Path
    target: Path
    damage: str | None  # None: the file was complete (copied as it was)
    rows_by_entity: dict[str, int]

    @property
    def samples(self) -> int:
        return self.rows_by_entity.get(SAMPLES_ENTITY, 0)

    def describe(self) -> str:
        state = "the file was complete" if self.damage is None else f"damaged: {self.damage}"
        return (
            f"recovered {self.samples} samples ({sum(self.rows_by_entity.values())} rows on "
            f"{len(self.rows_by_entity)} entities) from {self.source} ({state}) into {self.target}"
        )


def rerun_cli() -> Path:
    """The ``rerun`` executable of the installed wheel (beside this Python), else on PATH."""
    beside = Path(sys.executable).parent / "rerun"
    if beside.is_file():
        return beside
    found = shutil.which("rerun")
    if found is None:
        raise InputError("the rerun command line is not installed (pip install rerun-sdk)")
    return Path(found)


def check_rrd(path: Path) -> RrdCheck:
    """``rerun rrd verify`` on ``path``: ok, or the line saying what is wrong."""
    if not Path(path).is_file():
        raise InputError(f"{path}: file not found")
    result = _rerun("rrd", "verify", str(path))
    said = result.stdout + result.stderr
    if result.returncode == 0 and "0 files verified" in said:  # a cut header passes verify
        return RrdCheck(
            Path(path), False, "no recording in it (rerun rrd verify: 0 files verified)"
        )
    if result.returncode == 0:
        return RrdCheck(Path(path), True, None)
    lines = [line.strip() for line in said.splitlines() if line.strip()]
    problem = next((line for line in lines if "verif" not in line.lower()), None) or (
        lines[0] if lines else f"rerun rrd verify exited {result.returncode}"
    )
    return RrdCheck(Path(path), False, problem.replace(f'"{path}": ', ""))


def default_target(source: Path) -> Path:
    """``run.rrd`` -> ``run.recovered.rrd`` beside it."""
    return source.with_name(f"{source.stem}.recovered.rrd")


def recover_rrd(source: Path, target: Path | None = None) -> RrdRecovery:
    """Copy every complete chunk of ``source`` into a new, verified ``target``."""
    source = Path(source)
    target = default_target(source) if target is None else Path(target)
    if target.resolve() == source.resolve():
        raise InputError(f"{target}: the recovered file must not replace the damaged one")
    check = check_rrd(source)
    result = _rerun("rrd", "merge", "--continue-on-error", "-o", str(target), str(source))
    if result.returncode != 0 or not check_rrd(target).ok:
        remove_unfinished(target)
        raise InputError(f"{source}: nothing readable in it ({check.problem or 'not an .rrd'})")
    rows = rows_by_entity(target)
    if not rows:
        remove_unfinished(target)
        raise InputError(f"{source}: no complete chunk in it ({check.problem or 'empty'})")
    return RrdRecovery(source, target, check.problem, rows)


def rows_by_entity(path: Path) -> dict[str, int]:
    """Temporal rows per entity of a valid .rrd (static styles left out)."""
    from rerun.chunk import RrdReader

    rows: Counter[str] = Counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "no footer/manifest" on merged files: expected
        try:
            for chunk in RrdReader(path).stream():
                if not chunk.is_static:
                    rows[chunk.entity_path] += chunk.num_rows
        except ValueError:  # "No recording store found": nothing in it
            return {}
        except RuntimeError as err:
            raise InputError(f"{path}: not readable by Rerun: {err}") from err
    return dict(rows)


def _rerun(*args: str) -> subprocess.CompletedProcess[str]:
    try:
        return subprocess.run(
            [str(rerun_cli()), *args],
            capture_output=True,
            text=True,
            timeout=_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as err:
        raise InputError(f"rerun {' '.join(args[:2])} failed: {err}") from err
