"""Compose files merged as ``docker compose -f A -f B`` does, and a container's files on disk.

No Docker engine (nor the compose plugin) runs in CI, so the tests merge the
files themselves with the rules of the Compose Specification (merge.md):
mappings merge key by key; ``command``, ``entrypoint`` and ``healthcheck.test``
are replaced by the later file; ``volumes`` are merged by container path (a
later mount of the same target replaces the earlier one); other sequences
(``ports``, ``profiles``) are appended without duplicates. ``${VAR:?message}``
is interpolated from the environment given, and a missing one fails with its
message, as compose does.

:class:`ContainerFiles` lays out what one service sees at its mount targets
under a folder (config copied, identity linked), with absolute container paths
inside its TOML files rewritten to that folder, so its commands and station
files can run on this machine. :func:`host_path` maps a container path of the
plain file to the repository; :func:`config_files` reads a command's
``--config`` files as the CLI parses them.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from services.cli.main import build_parser
from tests.support.paths import REPO

BASE_FILE = REPO / "docker-compose.yml"
TLS_FILE = REPO / "docker-compose.tls.yml"
CERTS_SCRIPT = REPO / "config" / "security" / "make-compose-certs.sh"
IDENTITY = "/etc/boltwatch-identity"
REPLACED_SEQUENCES = {("command",), ("entrypoint",), ("healthcheck", "test")}
VARIABLE = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)(?::\?([^}]*))?\}")
MOUNT = re.compile(r"(.+):(/[^:]*)(?::ro|:rw)?")


class MissingVariableError(Exception):
    """A required ``${VAR:?message}`` that the environment does not set."""


def interpolate(value: Any, env: Mapping[str, str]) -> Any:
    """Every string of a parsed compose document with its ``${VAR}`` replaced."""
    if isinstance(value, dict):
        return {key: interpolate(item, env) for key, item in value.items()}
    if isinstance(value, list):
        return [interpolate(item, env) for item in value]
    if not isinstance(value, str):
        return value

    def variable(match: re.Match[str]) -> str:
        name, message = match.group(1), match.group(2)
        if env.get(name):
            return env[name]
        if message is not None:
            raise MissingVariableError(f"required variable {name} is missing a value: {message}")
        return ""

    return VARIABLE.sub(variable, value)


def load_merged(files: list[Path], env: Mapping[str, str]) -> dict[str, Any]:
    """The compose project of ``files`` merged in order, variables interpolated."""
    merged: dict[str, Any] = {}
    for file in files:
        merged = _merge(merged, interpolate(yaml.safe_load(file.read_text()), env), ())
    return merged


def make_compose_certs(
    out: Path, extra_identities: tuple[str, ...] = (), opcua_clients: tuple[str, ...] = ()
) -> None:
    """The identities of docker-compose.tls.yml, by config/security/make-compose-certs.sh
    (and ``extra_identities``, its ``EXTRA_IDENTITIES``; ``opcua_clients``, its
    ``OPCUA_CLIENTS``: none, its default)."""
    env = os.environ | {"EXTRA_IDENTITIES": " ".join(extra_identities)}
    if opcua_clients:
        env["OPCUA_CLIENTS"] = " ".join(opcua_clients)
    script = [str(CERTS_SCRIPT), str(out)]
    subprocess.run(script, check=True, capture_output=True, cwd=out.parent, env=env)


def certificate_field(pem: Path, option: str) -> str:
    """``-subject`` or ``-ext subjectAltName`` of a certificate, as the openssl CLI shows it."""
    shown = subprocess.run(
        ["openssl", "x509", "-in", str(pem), "-noout", "-nameopt", "RFC2253", *option.split()],
        check=True,
        capture_output=True,
        text=True,
    )
    return shown.stdout


def common_name(pem: Path) -> str:
    match = re.search(r"CN=([^,\n]+)", certificate_field(pem, "-subject"))
    assert match, f"{pem} has no common name"
    return match.group(1)


def split_volume(volume: str) -> tuple[str, str]:
    """``SOURCE:TARGET[:ro]`` -> (SOURCE, TARGET); SOURCE may be ``${VAR:?message}``."""
    match = MOUNT.fullmatch(volume)
    assert match, f"not a SOURCE:TARGET mount: {volume}"
    return match.group(1), match.group(2)


def host_path(container_path: str, volumes: list[str]) -> Path:
    """Map a path inside the container to the repository through the service's mounts."""
    for volume in volumes:
        source, target = split_volume(volume)
        if container_path.startswith(target + "/"):
            assert source.startswith("./"), f"{container_path} is not mounted from the repository"
            return (REPO / source / container_path[len(target) + 1 :]).resolve()
    raise AssertionError(f"{container_path} is not under any mount of {volumes}")


def config_files(command: list[str]) -> list[str]:
    """The ``--config`` files of a boltwatch command, one or several, as the CLI parses them."""
    config = build_parser().parse_args(command).config
    return [str(file) for file in (config if isinstance(config, list) else [config])]


def _merge(base: Any, override: Any, path: tuple[str, ...]) -> Any:
    if isinstance(base, dict) and isinstance(override, dict):
        result = dict(base)
        for key, value in override.items():
            result[key] = _merge(base[key], value, (*path, key)) if key in base else value
        return result
    if isinstance(base, list) and isinstance(override, list):
        if path[-1:] == ("volumes",) and len(path) == 3:  # services.NAME.volumes
            by_target = {split_volume(v)[1]: v for v in base}
            by_target |= {split_volume(v)[1]: v for v in override}
            return list(by_target.values())
        if path[-2:] in REPLACED_SEQUENCES or path[-1:] in REPLACED_SEQUENCES:
            return override
        return base + [item for item in override if item not in base]
    return override


class ContainerFiles:
    """What one service of the merged file sees at its mount targets, under ``root``.

    ``./config`` mounts are copied (their TOML files get container paths
    rewritten to ``root``); an identity folder is linked; other mounts (the
    recordings) become empty folders.
    """

    def __init__(self, root: Path, volumes: list[str]) -> None:
        self.root = root
        self.targets = sorted((split_volume(v)[1] for v in volumes), key=len, reverse=True)
        for volume in volumes:
            source, target = split_volume(volume)
            mirrored = self.host(target)
            mirrored.parent.mkdir(parents=True, exist_ok=True)
            if source.startswith("./"):
                shutil.copytree(REPO / source, mirrored)
                for toml in mirrored.rglob("*.toml"):
                    toml.write_text(self.rewrite(toml.read_text()))
            elif source.startswith("/"):
                mirrored.symlink_to(source, target_is_directory=True)
            else:  # a named volume
                mirrored.mkdir()

    def host(self, container_path: str) -> Path:
        """Where ``container_path`` is on this machine."""
        assert container_path.startswith("/"), container_path
        return self.root / container_path.lstrip("/")

    def mounted(self, container_path: str) -> bool:
        return any(container_path.startswith(target + "/") for target in self.targets)

    def rewrite(self, text: str) -> str:
        """Absolute container paths in quotes -> the same paths under ``root``."""
        for target in self.targets:
            pattern = re.compile(r'"' + re.escape(target) + r'(?=["/])')
            text = pattern.sub('"' + str(self.host(target)), text)
        return text

    def arguments(self, args: list[str]) -> list[str]:
        """A command line with its container paths mapped to this machine."""
        return [str(self.host(a)) if self.mounted(a) else a for a in args]
