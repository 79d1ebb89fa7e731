"""The OPC Foundation's NodeSet2 files the server is built from, fetched at install time.

The seven models (DI, IA, Machinery, Machinery/Result, AMB, IJT Base 1.01.0, IJT
Tightening 2.00.1) come from the npm package ``node-opcua-nodesets`` (MIT), at a
pinned version whose tarball is checked against its sha512 integrity before a
file of it is used. Nothing of them is in the repository: ``make`` runs
``python -m services.opcua.nodeset_files`` (``make opcua-nodesets``), which asks
``npm pack`` for the tarball into :data:`DEFAULT_FOLDER` (``.cache/opcua-nodesets/``
of the checkout, outside git) and extracts only :data:`NODESET_FILES`.

Without npm, the fetch says so in one line and leaves (exit status 0: the rest of
the project installs and tests without the OPC UA server); a tarball whose
integrity differs is an error (exit status 1) and nothing is extracted.
"""

from __future__ import annotations

import base64
import hashlib
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

#: the npm package and its pinned version (``npm view node-opcua-nodesets@VERSION dist``)
PACKAGE = "node-opcua-nodesets"
VERSION = "2.185.0"
#: ``dist.integrity`` of that version's tarball on the npm registry
INTEGRITY = (
    "sha512-"
    "7qDwdkYRKIGRBk0gKhY5C3olQ0wRHTCoZj4FbzD1GmXF5xGaZcv/OatvFa73H7yyq3LxWxTKVteELlbbyziyLg=="
)
#: the models in the order they are imported (each needs the ones before it)
NODESET_FILES = (
    "Opc.Ua.Di.NodeSet2.xml",
    "Opc.Ua.IA.NodeSet2.xml",
    "Opc.Ua.Machinery.NodeSet2.xml",
    "Opc.Ua.Machinery_Result.NodeSet2.xml",
    "Opc.Ua.AMB.NodeSet2.xml",
    "Opc.Ua.Ijt.Base.NodeSet2.xml",
    "Opc.Ua.Ijt.Tightening.NodeSet2.xml",
)
#: where they are inside the tarball
TARBALL_FOLDER = "package/nodesets/"
#: the checkout's cache (``services/`` sits in the checkout's root); BOLTWATCH_OPCUA_NODESETS
#: names another folder (an image that copies the files elsewhere)
DEFAULT_FOLDER = Path(__file__).resolve().parents[2] / ".cache" / "opcua-nodesets"
FOLDER_ENV = "BOLTWATCH_OPCUA_NODESETS"
FETCH_COMMAND = "make opcua-nodesets"


class NodesetFetchError(RuntimeError):
    """The files could not be fetched or did not check out: one line why."""


def nodeset_folder(folder: Path | None = None) -> Path:
    """The folder of the pinned version's files (``<cache>/<VERSION>/``)."""
    base = folder or Path(os.environ.get(FOLDER_ENV) or DEFAULT_FOLDER)
    return base / VERSION


def missing_files(folder: Path) -> list[str]:
    """The files of :data:`NODESET_FILES` not in ``folder``."""
    return [name for name in NODESET_FILES if not (folder / name).is_file()]


def integrity_of(tarball: Path) -> str:
    """npm's ``sha512-<base64>`` of a file."""
    digest = hashlib.sha512(tarball.read_bytes()).digest()
    return "sha512-" + base64.b64encode(digest).decode()


def fetch(folder: Path) -> None:
    """``npm pack`` the pinned tarball, check its integrity, extract the seven files into
    ``folder`` (written whole or not at all). NodesetFetchError on any failure."""
    npm = shutil.which("npm")
    if npm is None:
        raise NodesetFetchError("npm is not installed")
    folder.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder.parent) as scratch:
        packed = subprocess.run(
            [npm, "pack", f"{PACKAGE}@{VERSION}", "--silent", "--pack-destination", scratch],
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )
        if packed.returncode != 0:
            reason = (packed.stderr.strip().splitlines() or ["no output"])[-1]
            raise NodesetFetchError(f"npm pack {PACKAGE}@{VERSION} failed: {reason}")
        tarball = Path(scratch) / f"{PACKAGE}-{VERSION}.tgz"
        found = integrity_of(tarball)
        if found != INTEGRITY:
            raise NodesetFetchError(
                f"{tarball.name} has integrity {found}, expected {INTEGRITY}: not used"
            )
        extracted = Path(scratch) / "files"
        extracted.mkdir()
        with tarfile.open(tarball) as archive:
            for name in NODESET_FILES:
                member = archive.getmember(TARBALL_FOLDER + name)
                source = archive.extractfile(member)
                if source is None:
                    raise NodesetFetchError(f"{name} is not a file in {tarball.name}")
                (extracted / name).write_bytes(source.read())
        if folder.exists():
            shutil.rmtree(folder)
        extracted.rename(folder)


def main() -> int:
    """Fetch the files unless they are there; 0 also when npm is missing (one line)."""
    folder = nodeset_folder()
    if not missing_files(folder):
        return 0
    try:
        fetch(folder)
    except NodesetFetchError as err:
        if shutil.which("npm") is None:
            print(f"opcua nodesets: skipped ({err}); `boltwatch serve opcua` needs them")
            return 0
        print(f"opcua nodesets: {err}", file=sys.stderr)
        return 1
    print(f"opcua nodesets: {PACKAGE}@{VERSION} checked, {len(NODESET_FILES)} files in {folder}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
