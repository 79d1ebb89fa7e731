"""The image's OPC UA models: the Dockerfile's ``opcua-nodesets`` stage, its command run here.

No Docker engine here: the stage's RUN is run as the stage runs it (npm and
python3 on the PATH, the fetch's one file copied as the stage copies it), with
its folder under a temporary one. It fetches the pinned version's seven files
(services/opcua/nodeset_files.py: npm pack, sha512 checked) where the final
stage's ``COPY --from`` and ``BOLTWATCH_OPCUA_NODESETS`` make ``serve opcua``
look, and fails without npm: no image is built that cannot serve.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from services.opcua.nodeset_files import FOLDER_ENV, missing_files, nodeset_folder
from tests.support.paths import REPO

STAGE = "opcua-nodesets"


def stages(dockerfile: str) -> dict[str, list[str]]:
    """Each stage's instructions (continuation lines joined), by its ``AS`` name ("" last)."""
    text = re.sub(r"\\\n\s*", "", dockerfile)
    found: dict[str, list[str]] = {}
    current: list[str] = []
    for line in text.splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if line.startswith("FROM "):
            name = re.search(r" AS (\S+)$", line)
            current = found.setdefault(name.group(1) if name else "", [])
        current.append(line)
    return found


def test_the_image_fetches_the_models_where_the_server_looks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    built = stages((REPO / "Dockerfile").read_text())
    stage, final = built[STAGE], built[""]
    [copy] = [line for line in stage if line.startswith("COPY ")]
    assert copy == "COPY services/opcua/nodeset_files.py services/opcua/"
    [fetch] = [line.removeprefix("RUN ") for line in stage if "fetch(" in line]
    fetched = re.search(rf"{FOLDER_ENV}=(\S+) ", fetch)
    assert fetched, f"the stage's fetch must set {FOLDER_ENV}"
    [copied] = [line.split()[1:] for line in final if line.startswith(f"COPY --from={STAGE}")]
    assert copied[1] == fetched.group(1), "the final stage copies what the stage fetched"
    image_folder = copied[2]
    assert f"ENV {FOLDER_ENV}={image_folder}" in final
    if shutil.which("npm") is None:
        pytest.skip("needs npm (the stage's node image has it)")
    build = tmp_path / "build"
    (build / "services" / "opcua").mkdir(parents=True)
    shutil.copy(REPO / "services" / "opcua" / "nodeset_files.py", build / "services" / "opcua")
    fetched_here = tmp_path / fetched.group(1).lstrip("/")
    command = fetch.replace(fetched.group(1), str(fetched_here))
    command = command.replace("python3 ", f"{sys.executable} ", 1)
    ran = subprocess.run(
        ["sh", "-c", command], cwd=build, capture_output=True, text=True, check=False
    )
    assert ran.returncode == 0, ran.stderr
    in_image = tmp_path / image_folder.lstrip("/")
    shutil.copytree(fetched_here, in_image)  # COPY --from
    monkeypatch.setenv(FOLDER_ENV, str(in_image))  # the image's ENV
    assert missing_files(nodeset_folder()) == []
    nothing = tmp_path / "empty-path"  # a PATH without npm (python is named by its path)
    nothing.mkdir()
    without_npm = subprocess.run(
        [shutil.which("sh") or "/bin/sh", "-c", command.replace(str(fetched_here), str(nothing))],
        cwd=build,
        capture_output=True,
        text=True,
        env={"PATH": str(nothing)},
        check=False,
    )
    assert without_npm.returncode != 0, "no image without its models"
    assert "npm is not installed" in without_npm.stderr
