"""``boltwatch`` as a real process whose output cannot go where it should: a pipe closed by
its reader (``boltwatch predict ... | head -1``) and a file size limit (EFBIG mid-write).

These need a process of their own: the pipe's reader is ``head``, and the file size limit
is a resource limit of the process.
"""

from __future__ import annotations

import fcntl
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

from services.cli.main import main
from tests.support.bad_arguments import Workspace
from tests.support.paths import REPO, STATION_FILE

#: Linux's fcntl to size a pipe's buffer (fcntl.F_SETPIPE_SZ from Python 3.10 on)
F_SETPIPE_SZ = getattr(fcntl, "F_SETPIPE_SZ", 1031)
PIPE_BYTES = 4096


def boltwatch(*args: str) -> list[str]:
    return [sys.executable, "-m", "services.cli", *args]


def test_predict_into_a_pipe_whose_reader_left_stops_quietly(tmp_path: Path) -> None:
    """``head -1`` reads its line and exits while ``predict`` still writes: no traceback, no
    message, exit status 141 (128 + SIGPIPE), as a shell reports for any tool in its place."""
    trace = tmp_path / "run.csv"
    assert main(["simulate", "--config", str(STATION_FILE), "--out", str(trace)]) == 0
    predict = subprocess.Popen(
        boltwatch("predict", str(trace), "--target-force", "56000"),
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert predict.stdout is not None and predict.stderr is not None
    # A small pipe: predict's ~20 kB of JSON Lines cannot all be in it when head leaves.
    fcntl.fcntl(predict.stdout.fileno(), F_SETPIPE_SZ, PIPE_BYTES)
    head = subprocess.run(
        ["head", "-1"], stdin=predict.stdout, capture_output=True, timeout=60, check=False
    )
    predict.stdout.close()  # head was the only reader left
    err = predict.stderr.read().decode()
    predict.stderr.close()
    assert predict.wait(timeout=60) == 141, err  # main.EXIT_READER_GONE
    assert err == ""
    assert head.stdout.decode().startswith('{"type": "event"')


def _file_size_limit(limit_bytes: int) -> None:
    """In the child, before exec: writes past ``limit_bytes`` fail with EFBIG."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # else the kernel kills the writer
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))


def test_a_write_cut_by_a_file_size_limit_names_the_file() -> None:
    """The write fails mid-file with EFBIG; the OSError of a write names no file, the line
    does (``shared.errors.naming``)."""
    with Workspace() as space:
        result = subprocess.run(
            boltwatch("export", "good.mcap", "--out", "run.csv"),
            check=False,
            cwd=space.path,
            # no .pyc: the limit would cut them short for every later import
            env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin", "PYTHONDONTWRITEBYTECODE": "1"},
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=lambda: _file_size_limit(1000),
        )
    assert result.returncode == 2, result.stderr
    assert result.stderr == (
        "boltwatch export: run.csv: file too large (a file size limit was reached)\n"
    )


def test_a_command_started_with_its_output_closed_runs_all_the_same(tmp_path: Path) -> None:
    """``boltwatch predict ... >&-``: Python has no sys.stdout then (it was an AttributeError);
    what would be printed goes to /dev/null, as a service under a supervisor needs."""
    trace = tmp_path / "run.csv"
    assert main(["simulate", "--config", str(STATION_FILE), "--out", str(trace)]) == 0
    result = subprocess.run(
        boltwatch("predict", str(trace), "--target-force", "56000"),
        cwd=REPO,
        stderr=subprocess.PIPE,
        text=True,
        timeout=60,
        check=False,
        preexec_fn=lambda: os.close(1),
    )
    assert (result.returncode, result.stderr) == (0, "")
