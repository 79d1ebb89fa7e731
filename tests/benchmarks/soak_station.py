"""Soak: the simulated station for an hour (or ``--duration-s``), then the books.

Runs ``boltwatch up`` on an isolated copy of ``config/station.toml`` (own
zenoh port, own CAN multicast port, recordings in ``--folder``) with more
runs than fit in the duration, samples the resident memory of every station
process every ``--every-s`` seconds, and ends it with SIGTERM (the same clean
stop as Ctrl-C; SIGINT is ignored when the soak runs under nohup). Then it
reads every MCAP file back with the standard mcap reader and compares:

- samples the acquisition counted on CAN (its last ``bus`` message, plus
  those it counted as missed) against samples recorded in MCAP;
- runs and decisions in the recordings against the rows ``up`` printed;
- memory of each service: first sample after the warm-up against the last,
  as growth per hour.

Not part of ``make test``::

    .venv/bin/python tests/benchmarks/soak_station.py --duration-s 3600
"""

from __future__ import annotations

import argparse
import json
import signal
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

from mcap.reader import make_reader

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from tests.support.station_files import child_pids, command_line, write_station

SECONDS_PER_RUN_AT_MOST = 1.0  # program 1 takes about 2 s a run: never too few runs
WARM_UP_S = 60.0


def service_name(pid: int) -> str:
    words = command_line(pid).split()
    if "serve" in words:
        return words[words.index("serve") + 1]
    return "up" if "up" in words else Path(words[0]).name if words else "?"


def rss_kib(pid: int) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        return None
    return None


def station_processes(up_pid: int) -> dict[str, int]:
    return {service_name(pid): pid for pid in child_pids(up_pid)}


def count_recordings(folder: Path) -> dict[str, object]:
    """Samples, runs, decisions and the acquisition's last counters, from MCAP alone."""
    samples = 0
    runs = 0
    decisions = 0
    gaps = 0
    last_bus: dict[str, object] = {}
    files = sorted(folder.rglob("*.mcap"))
    for path in files:
        with path.open("rb") as handle:
            previous_sequence: dict[int, int] = {}
            for _schema, channel, message in make_reader(handle).iter_messages():
                topic = channel.topic.rsplit("/", 1)[-1]
                if topic == "samples":
                    samples += 1
                    body = json.loads(message.data)
                    run_id, sequence = body["run_id"], body["sequence"]
                    if run_id in previous_sequence and sequence != previous_sequence[run_id] + 1:
                        gaps += 1
                    previous_sequence[run_id] = sequence
                elif topic == "runs":
                    runs += 1
                elif topic == "decision":
                    decisions += 1
                elif topic == "bus":
                    body = json.loads(message.data)
                    if body["time_ns"] >= int(str(last_bus.get("time_ns", 0))):
                        last_bus = body
    return {
        "files": len(files),
        "samples": samples,
        "sequence_gaps": gaps,
        "runs": runs,
        "decisions": decisions,
        "last_bus": last_bus,
    }


def memory_growth(series: dict[str, list[tuple[float, int]]]) -> dict[str, dict[str, float]]:
    growth: dict[str, dict[str, float]] = {}
    for name, points in series.items():
        settled = [(t, kib) for t, kib in points if t >= WARM_UP_S] or points
        (t0, first), (t1, last) = settled[0], settled[-1]
        hours = max(t1 - t0, 1.0) / 3600.0
        growth[name] = {
            "rss_first_mib": round(first / 1024, 1),
            "rss_last_mib": round(last / 1024, 1),
            "rss_max_mib": round(max(kib for _t, kib in points) / 1024, 1),
            "growth_mib_per_h": round((last - first) / 1024 / hours, 2),
        }
    return growth


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration-s", type=float, default=3600.0)
    parser.add_argument("--every-s", type=float, default=30.0, help="memory sampling period")
    parser.add_argument("--folder", type=Path, default=None, help="work folder (default: temp)")
    parser.add_argument("--out", type=Path, default=None, help="write the result as JSON here")
    args = parser.parse_args()
    folder = args.folder or Path(tempfile.mkdtemp(prefix="boltwatch-soak-"))
    folder.mkdir(parents=True, exist_ok=True)
    station_file = write_station(folder)
    runs = int(args.duration_s / SECONDS_PER_RUN_AT_MOST) + 10
    out_path = folder / "up.out"
    command = [sys.executable, "-m", "services.cli", "up", "--config", str(station_file)]
    command += ["--runs", str(runs)]
    print(f"soak: {args.duration_s:.0f} s in {folder}", flush=True)
    with out_path.open("w") as out:
        up = subprocess.Popen(command, cwd=REPO, stdout=out, stderr=subprocess.STDOUT)
        started = time.monotonic()
        series: dict[str, list[tuple[float, int]]] = defaultdict(list)
        try:
            while (elapsed := time.monotonic() - started) < args.duration_s:
                if up.poll() is not None:
                    print(f"boltwatch up ended early with {up.returncode}", file=sys.stderr)
                    break
                for name, pid in station_processes(up.pid).items():
                    kib = rss_kib(pid)
                    if kib is not None:
                        series[name].append((elapsed, kib))
                print(
                    f"  {elapsed:7.0f} s  "
                    + "  ".join(
                        f"{name} {points[-1][1] / 1024:.0f} MiB" for name, points in series.items()
                    ),
                    flush=True,
                )
                time.sleep(min(args.every_s, max(args.duration_s - elapsed, 0.1)))
        finally:
            if up.poll() is None:
                up.send_signal(signal.SIGTERM)  # SIGINT is ignored under nohup
            up.wait(120)
    elapsed_s = time.monotonic() - started
    text = out_path.read_text()
    printed_runs = {line.split()[0] for line in text.splitlines() if line.strip()[:1].isdigit()}
    recorded = count_recordings(station_file.parent / "recordings")
    bus = recorded["last_bus"]
    assert isinstance(bus, dict)
    result = {
        "duration_s": round(elapsed_s, 1),
        "up_exit": up.returncode,
        "runs_printed_by_up": len(printed_runs),
        "acquisition_samples": bus.get("samples"),
        "acquisition_missed": bus.get("missed_samples"),
        "recorded": {k: v for k, v in recorded.items() if k != "last_bus"},
        "memory": memory_growth(series),
        "folder": str(folder),
    }
    print(json.dumps(result, indent=2))
    if args.out:
        args.out.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
