"""Throwaway OPC UA application instance certificates for tests, made with the openssl CLI.

OPC UA's Basic256Sha256 wants RSA keys and certificates whose subjectAltName
names the application's URI (``URI:...``) and whose key usage allows signing and
encryption. :func:`make_opcua_certificates` makes a test CA, the server's
certificate (self-signed: a server's certificate is trusted by its clients
directly) and one client certificate per name signed by the CA; the trusted
clients folder holds the CA only (a client the CA did not sign is refused).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

SERVER_URI = "urn:boltwatch:test:opcua-server"
KEY_USAGE = "critical,digitalSignature,nonRepudiation,keyEncipherment,dataEncipherment"


@dataclass(frozen=True)
class OpcuaCertificates:
    server_certificate: Path
    server_key: Path
    trusted_clients: Path  # the CA's certificate
    clients: dict[str, tuple[Path, Path]]  # name -> (certificate, key), signed by the CA


def client_uri(name: str) -> str:
    return f"urn:boltwatch:test:{name}"


def _openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], check=True, capture_output=True, cwd=cwd)


def _extensions(folder: Path, name: str, lines: list[str]) -> Path:
    path = folder / f"{name}.ext"
    path.write_text("\n".join(lines) + "\n")
    return path


def make_opcua_certificates(
    folder: Path, clients: tuple[str, ...] = ("client",), untrusted: tuple[str, ...] = ()
) -> OpcuaCertificates:
    """Files under ``folder``; ``untrusted`` clients are self-signed (not by the CA)."""
    folder.mkdir(parents=True, exist_ok=True)
    trusted = folder / "trusted"
    trusted.mkdir(exist_ok=True)
    ca_ext = _extensions(
        folder, "ca", ["basicConstraints=critical,CA:TRUE", "keyUsage=critical,keyCertSign,cRLSign"]
    )
    _openssl("genrsa", "-out", "ca.key", "2048", cwd=folder)
    _openssl(
        "req",
        "-x509",
        "-new",
        "-key",
        "ca.key",
        "-days",
        "2",
        "-subj",
        "/CN=boltwatch test CA",
        "-extensions",
        "v3",
        "-config",
        str(_config(folder, ca_ext)),
        "-out",
        "trusted/ca.pem",
        cwd=folder,
    )
    server_ext = _extensions(
        folder,
        "server",
        [
            "basicConstraints=critical,CA:FALSE",
            f"keyUsage={KEY_USAGE}",
            "extendedKeyUsage=serverAuth,clientAuth",
            f"subjectAltName=URI:{SERVER_URI},DNS:localhost,IP:127.0.0.1",
        ],
    )
    _openssl("genrsa", "-out", "server.key", "2048", cwd=folder)
    _openssl(
        "req",
        "-x509",
        "-new",
        "-key",
        "server.key",
        "-days",
        "2",
        "-subj",
        "/CN=boltwatch test server",
        "-extensions",
        "v3",
        "-config",
        str(_config(folder, server_ext)),
        "-out",
        "server.pem",
        cwd=folder,
    )
    made: dict[str, tuple[Path, Path]] = {}
    for name in (*clients, *untrusted):
        ext = _extensions(
            folder,
            name,
            [
                "basicConstraints=critical,CA:FALSE",
                f"keyUsage={KEY_USAGE}",
                "extendedKeyUsage=clientAuth",
                f"subjectAltName=URI:{client_uri(name)},DNS:localhost",
            ],
        )
        _openssl("genrsa", "-out", f"{name}.key", "2048", cwd=folder)
        if name in untrusted:
            _openssl(
                "req",
                "-x509",
                "-new",
                "-key",
                f"{name}.key",
                "-days",
                "2",
                "-subj",
                f"/CN={name}",
                "-extensions",
                "v3",
                "-config",
                str(_config(folder, ext)),
                "-out",
                f"{name}.pem",
                cwd=folder,
            )
        else:
            _openssl(
                "req",
                "-new",
                "-key",
                f"{name}.key",
                "-subj",
                f"/CN={name}",
                "-out",
                f"{name}.csr",
                cwd=folder,
            )
            _openssl(
                "x509",
                "-req",
                "-in",
                f"{name}.csr",
                "-CA",
                "trusted/ca.pem",
                "-CAkey",
                "ca.key",
                "-CAcreateserial",
                "-days",
                "2",
                "-extfile",
                str(ext),
                "-out",
                f"{name}.pem",
                cwd=folder,
            )
        made[name] = (folder / f"{name}.pem", folder / f"{name}.key")
    return OpcuaCertificates(folder / "server.pem", folder / "server.key", trusted, made)


def _config(folder: Path, extensions: Path) -> Path:
    """An openssl req config whose ``v3`` section is ``extensions``."""
    path = folder / f"{extensions.stem}.cnf"
    path.write_text("[req]\ndistinguished_name = dn\n[dn]\n[v3]\n" + extensions.read_text())
    return path
