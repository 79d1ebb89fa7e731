"""``boltwatch import``: the real CS351 runs become recordings like live ones; bad files say so.

The four real runs shipped in ``tests/data/cs351-real-runs`` are always
imported (a bare clone has nothing else); the ten of the team handbook
(``../shared/data/cs351-real-runs``) are the same check, wider, skipped with
the reason where they are not beside the checkout. Each is imported into
MCAP with the recorder's own writer, read back with the mcap reader (samples
decoded with ``json`` alone), and opened by ``boltwatch export`` and
``boltwatch inspect``. Broken copies (cut, wrong types, missing fields) each
give one line naming the file and the fault, and do not stop the others.
"""

from __future__ import annotations

import csv
import json
import shutil
from datetime import UTC, datetime
from pathlib import Path

import pytest
from mcap.reader import make_reader

from services.cli.main import main
from shared.contract import SCHEMA_TYPES, json_schema, read_trace
from shared.offline.controller_import import read_controller_run
from tests.support.paths import HANDBOOK_REAL_RUNS, PROJECT_REAL_RUNS

SHIPPED = sorted(PROJECT_REAL_RUNS.glob("Ch_*.json"))
HANDBOOK = sorted(HANDBOOK_REAL_RUNS.glob("Ch_*.json"))
NEEDS_HANDBOOK = pytest.mark.skipif(
    len(HANDBOOK) != 10,
    reason=f"the ten real runs of the team handbook are not beside the checkout "
    f"({HANDBOOK_REAL_RUNS}); the four shipped ones are checked instead",
)
REAL_RUN_SETS = [
    pytest.param(SHIPPED, id="shipped-4"),
    pytest.param(HANDBOOK, id="handbook-10", marks=NEEDS_HANDBOOK),
]


def test_the_project_ships_real_runs_of_both_classes_with_source_and_licence() -> None:
    assert [path.name for path in SHIPPED] == [
        "Ch_000001596334.json",
        "Ch_000001596339.json",
        "Ch_000001621524.json",
        "Ch_000001621527.json",
    ]
    readme = (PROJECT_REAL_RUNS / "README.md").read_text()
    for needed in ("CC BY 4.0", "West", "Deuse", "arXiv:2505.11925", "test extract"):
        assert needed in readme
    with (PROJECT_REAL_RUNS / "labels.csv").open() as handle:
        labels = list(csv.DictReader(handle))
    assert [row["file_name"] for row in labels] == [path.name for path in SHIPPED]
    assert {row["class_value"] for row in labels} == {"001_test-class-1", "101_test-class-2"}
    for row in labels:
        run = read_controller_run(PROJECT_REAL_RUNS / row["file_name"])
        assert str(run.run_id) == row["run_id"]
        assert run.verdict.part_id == row["workpiece_id"]


@pytest.mark.parametrize("runs", REAL_RUN_SETS)
def test_every_real_run_imports_as_a_live_recording(
    runs: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    args = ["import", *map(str, runs), "--recordings", str(recordings), "--no-rerun"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[-1] == (
        f"imported {len(runs)} of {len(runs)} runs into {recordings}, 0 already there, 0 refused"
    )

    for source in runs:
        run = read_controller_run(source)
        (path,) = recordings.glob(f"cs351/{_day(run.started_ns)}/cs351_run{run.run_id}_*.mcap")
        with path.open("rb") as handle:
            reader = make_reader(handle)
            summary = reader.get_summary()
            assert summary is not None
            schemas = {schema.id: schema for schema in summary.schemas.values()}
            channels = {c.topic: c for c in summary.channels.values()}
            for topic, channel in channels.items():  # every channel schema'd, as live
                schema = schemas[channel.schema_id]
                assert channel.message_encoding == "json"
                assert json.loads(schema.data) == json_schema(SCHEMA_TYPES[schema.name]), topic
            assert {"boltwatch/cs351/samples", "boltwatch/cs351/tool"} <= set(channels)
            samples = [
                (message, json.loads(message.data))  # json alone, no code of ours
                for _, channel, message in reader.iter_messages(topics=["boltwatch/cs351/samples"])
            ]
        with path.open("rb") as handle:
            metadata = {r.name: r.metadata for r in make_reader(handle).iter_metadata()}
        assert len(samples) == len(run)
        assert [data["torque_nm"] for _, data in samples] == run.torque_nm
        assert [data["force_n"] for _, data in samples] == [None] * len(run)
        times = [data["time_ns"] for _, data in samples]
        assert times == [run.date_ns + round(t * 1e9) for t in run.time_s]  # own timing
        assert [m.log_time for m, _ in samples] == times
        assert [m.sequence for m, _ in samples] == list(range(len(run)))
        assert metadata["station"]["station"] == "cs351"
        assert metadata["run"] == {
            "run_id": str(run.run_id),
            "tool_id": str(run.tool_id),
            "program_id": str(run.program_id),
        }
        assert metadata["controller"]["source_file"] == source.name
        assert metadata["controller"]["hardware"] == "CS351"

    first = read_controller_run(runs[0])
    assert len(set(first.time_s)) < len(first)  # the repeated timestamps stayed


def _day(time_ns: int) -> str:
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d}"


def test_export_inspect_and_rerun_work_on_an_imported_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    assert (
        main(["import", str(SHIPPED[0]), "--recordings", str(recordings), "--station", "l2"]) == 0
    )
    (mcap,) = recordings.glob("l2/2022-09-05/l2_run1596334_134339.mcap")
    assert mcap.with_suffix(".rrd").is_file()

    out_csv = tmp_path / "run.csv"
    assert main(["export", str(mcap), "--out", str(out_csv)]) == 0
    trace = read_trace(out_csv)
    run = read_controller_run(SHIPPED[0])
    assert len(trace) == len(run) and not trace.has_force
    assert list(trace.torque_nm) == pytest.approx(run.torque_nm, abs=1e-4)

    png = tmp_path / "run.png"
    assert main(["inspect", str(mcap), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000

    capsys.readouterr()
    again = main(["import", str(SHIPPED[0]), "--recordings", str(recordings), "--station", "l2"])
    out = capsys.readouterr().out
    assert again == 0 and "already in" in out
    assert out.splitlines()[-1].startswith("imported 0 of 1 runs")  # skipped is not imported
    assert out.splitlines()[-1].endswith(", 1 already there, 0 refused")
    assert len(list(recordings.glob("l2/*/*.mcap"))) == 1  # never a second copy


def test_csv_output_stays_available(tmp_path: Path) -> None:
    assert main(["import", str(SHIPPED[0]), "--csv", str(tmp_path)]) == 0
    trace = read_trace(tmp_path / f"{SHIPPED[0].stem}.csv")
    assert len(trace) == len(read_controller_run(SHIPPED[0]))


def broken_copies(folder: Path) -> dict[str, tuple[Path, str]]:
    """name -> (a broken copy of a real run, what its error must say)."""
    text = SHIPPED[0].read_text()
    document = json.loads(text)
    out: dict[str, tuple[Path, str]] = {}

    def put(name: str, content: str, expected: str) -> None:
        path = folder / f"{name}.json"
        path.write_text(content)
        out[name] = (path, expected)

    put("cut", text[: len(text) // 2], "not valid JSON (truncated or corrupt?)")
    put("empty", "", "not valid JSON")
    wrong = json.loads(text)
    wrong["tightening steps"][1]["graph"]["torque values"][5] = "1.2"
    put("wrong_type", json.dumps(wrong), "tightening steps[1].graph.torque values[5]: expected")
    nan = json.loads(text)
    nan["tightening steps"][0]["graph"]["angle values"][2] = float("nan")
    put("nan", json.dumps(nan), "angle values[2]: expected a finite number, got nan")
    short = json.loads(text)
    short["tightening steps"][2]["graph"]["time values"].pop()
    put("short", json.dumps(short), "tightening steps[2].graph: the lists differ in length")
    no_graph = json.loads(text)
    del no_graph["tightening steps"][3]["graph"]
    put("no_graph", json.dumps(no_graph), "tightening steps[3]: no 'graph' object")
    no_cycle = dict(document)
    del no_cycle["cycle"]
    put("no_cycle", json.dumps(no_cycle), "'cycle': expected an integer, got nothing")
    bad_date = dict(document, date="yesterday")
    put("bad_date", json.dumps(bad_date), "'date': expected 'YYYY-MM-DD HH:MM:SS'")
    put("not_a_run", json.dumps([1, 2]), "expected a JSON object (a CS351 run), got list")
    bad_nominal = json.loads(text)
    bad_nominal["tightening steps"][3]["tightening functions"][0]["nom"] = "1.4"
    put(
        "bad_nominal",
        json.dumps(bad_nominal),
        "tightening steps[3].tightening functions[0].nom: expected a finite number, got '1.4'",
    )
    return out


def test_broken_controller_files_each_give_one_line_and_the_good_ones_are_imported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = broken_copies(tmp_path)
    good = [tmp_path / SHIPPED[1].name, tmp_path / SHIPPED[2].name]
    for source, path in zip(SHIPPED[1:3], good, strict=True):
        shutil.copyfile(source, path)
    inputs = [good[0], *(path for path, _ in broken.values()), good[1]]
    recordings = tmp_path / "recordings"

    status = main(["import", *map(str, inputs), "--recordings", str(recordings), "--no-rerun"])

    assert status == 2  # some refused
    captured = capsys.readouterr()
    errors = captured.err.strip().splitlines()
    assert len(errors) == len(broken)  # one line per bad file
    for (path, expected), line in zip(broken.values(), errors, strict=True):
        assert line.startswith(f"boltwatch import: {path}: "), line
        assert expected in line, line
    assert captured.out.splitlines()[-1] == (
        f"imported 2 of {len(inputs)} runs into {recordings}, 0 already there, "
        f"{len(broken)} refused"
    )
    assert len(list(recordings.glob("cs351/*/*.mcap"))) == 2
