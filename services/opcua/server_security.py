"""Who may connect to the OPC UA server, from the command line's options, checked at start.

By default (:class:`SecuritySettings` with ``anonymous_read_only`` False) the only
endpoint is Basic256Sha256 Sign & Encrypt and every session needs a user:

- the channel: the server shows its own certificate (``--certificate``, RSA, PEM
  or DER, its subjectAltName naming the server's application URI as
  ``URI:...``) and key (``--private-key``, PEM), and accepts a client only when
  the client's application instance certificate is in, or signed by a CA in,
  ``--trusted-clients DIR`` (PEM or DER files), is within its validity, names
  the client's application URI, and allows client authentication and the key
  usages OPC UA asks (digitalSignature, nonRepudiation, keyEncipherment,
  dataEncipherment). A client without a certificate finds no endpoint it can use;
- the session: a UserName token whose name is in ``--users FILE``
  (:mod:`.users_file`) and whose password matches its hash
  (:mod:`.password_hashes`, compared in constant time); an anonymous session,
  an unknown name or a wrong password is refused (``BadUserAccessDenied``, or
  ``BadIdentityTokenRejected`` for a token the endpoint does not offer); a user of role
  ``operator`` also acknowledges the alerts' conditions (:func:`operators`).

``--anonymous-read-only`` adds an endpoint without security (None) and the
anonymous user, on every endpoint (asyncua offers one set of user tokens for
all; an anonymous session on the encrypted endpoint reads no more than one on
None): anyone who reaches the port reads the address space. It is refused with
``--users``: asyncua would offer the UserName token on the None endpoint too and
take its password in clear (a UserName token without an EncryptionAlgorithm),
so a password could cross the network unencrypted. Nothing in the address space
is writable by a client in any mode; every user is a reader.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua import Server, ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.crypto.truststore import TrustStore
from asyncua.crypto.validator import CertificateValidator, CertificateValidatorOptions
from asyncua.server.user_managers import UserManager
from cryptography import x509
from cryptography.hazmat.primitives.asymmetric import rsa

from services.opcua.client_sessions import use_client_sessions
from services.opcua.password_hashes import unknown_user_hash, verify, verify_unknown
from services.opcua.refusal_log import LoggedValidator, quiet_refusals
from services.opcua.users_file import OPERATOR, OpcuaUser, others_may_read, read_users
from shared.errors import ConfigError

LOG = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class SecuritySettings:
    """The files and the mode the options name."""

    certificate: Path | None
    private_key: Path | None
    trusted_clients: Path | None
    users: Path | None
    anonymous_read_only: bool = False

    def check(self) -> None:
        """ConfigError naming the option when the settings cannot make a server."""
        given = {
            "--certificate": self.certificate,
            "--private-key": self.private_key,
            "--trusted-clients": self.trusted_clients,
            "--users": self.users,
        }
        if self.anonymous_read_only and self.users is not None:
            raise ConfigError(
                "give --users or --anonymous-read-only, not both: asyncua would offer user "
                "names on the endpoint without security too and take a password there in clear"
            )
        if not self.anonymous_read_only:
            missing = [name for name, path in given.items() if path is None]
            if missing:
                raise ConfigError(
                    f"give {', '.join(missing)} (Basic256Sha256 sign and encrypt with user "
                    "names, the default), or --anonymous-read-only for a server anyone may read"
                )
        if (self.certificate is None) != (self.private_key is None):
            raise ConfigError("give --certificate and --private-key together")
        for name, path in given.items():
            if path is None:
                continue
            wanted_dir = name == "--trusted-clients"
            if not (path.is_dir() if wanted_dir else path.is_file()):
                kind = "a folder" if wanted_dir else "a file"
                raise ConfigError(f"{name} {path}: not {kind}")
        if self.users is not None:
            server_users(self.users)

    @property
    def secure(self) -> bool:
        return self.certificate is not None


def application_uri_of(certificate: Path) -> str:
    """The URI in the certificate's subjectAltName (the server's application URI); ConfigError
    when it has none or its key is not RSA (Basic256Sha256 needs RSA)."""
    data = certificate.read_bytes()
    try:
        cert = (
            x509.load_pem_x509_certificate(data)
            if b"-----BEGIN" in data
            else x509.load_der_x509_certificate(data)
        )
    except ValueError as err:
        raise ConfigError(f"--certificate {certificate}: not a PEM or DER certificate") from err
    if not isinstance(cert.public_key(), rsa.RSAPublicKey):
        raise ConfigError(f"--certificate {certificate}: Basic256Sha256 needs an RSA key")
    try:
        names = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName)
    except x509.ExtensionNotFound as err:
        raise ConfigError(
            f"--certificate {certificate}: no subjectAltName (it names the application URI)"
        ) from err
    uris = names.value.get_values_for_type(x509.UniformResourceIdentifier)
    if not uris:
        raise ConfigError(
            f"--certificate {certificate}: its subjectAltName has no URI:... (the "
            "server's application URI)"
        )
    return str(uris[0])


def server_users(path: Path) -> dict[str, OpcuaUser]:
    """The users of ``--users FILE``; ConfigError when it is bad or names nobody."""
    users = read_users(path)
    if not users:
        raise ConfigError(
            f"--users {path}: users: no user (add one: boltwatch opcua-user add NAME --users "
            f"{path})"
        )
    return users


def operators(settings: SecuritySettings) -> frozenset[str]:
    """The users of the users file that may act on conditions (role ``operator``)."""
    if settings.users is None:
        return frozenset()
    return frozenset(
        name for name, user in read_users(settings.users).items() if user.role == OPERATOR
    )


class PasswordUsers(UserManager):
    """asyncua's user manager: a session's user from its token (None: refused).

    asyncua asks it at each ActivateSession, in the server's loop, with the name and
    the password of a UserName token (decrypted), or no name for an anonymous one (refused:
    the users file and anonymous sessions do not go together)."""

    def __init__(self, users: Mapping[str, OpcuaUser]) -> None:
        self._users = dict(users)
        #: what an unknown name is checked against: the file's dearest hash's cost
        self.unknown_hash = unknown_user_hash(user.password_hash for user in users.values())

    def get_user(
        self,
        iserver: Any,
        username: str | None = None,
        password: str | None = None,
        certificate: Any = None,
    ) -> User | None:
        if username is None:
            return None
        user = self._users.get(username)
        # one scrypt either way: a wrong name takes as long as the dearest user's wrong password
        if user is None:
            matches = verify_unknown(password or "", self.unknown_hash)
        else:
            matches = verify(password or "", user.password_hash)
        if not matches:
            LOG.warning("OPC UA user %r refused: unknown name or wrong password", username)
            return None
        return User(role=UserRole.User, name=username)


async def apply(server: Server, settings: SecuritySettings) -> None:
    """Endpoints, user tokens and users, certificate and client validation of ``server``; its
    sessions :class:`~.client_sessions.ClientSession`, one line per refusal
    (:mod:`.refusal_log`)."""
    settings.check()
    quiet_refusals()
    use_client_sessions(server)
    policies: list[ua.SecurityPolicyType] = []
    tokens: list[type] = []
    if settings.anonymous_read_only:
        tokens.append(ua.AnonymousIdentityToken)
    if settings.users is not None:
        tokens.append(ua.UserNameIdentityToken)
        if others_may_read(settings.users):
            LOG.warning(
                "--users %s: anyone on this host may read it (its password hashes); chmod o-r it",
                settings.users,
            )
        users = server_users(settings.users)
        server.iserver.set_user_manager(PasswordUsers(users))
    if settings.secure:
        assert settings.certificate is not None and settings.private_key is not None
        await server.set_application_uri(application_uri_of(settings.certificate))
        try:
            await server.load_certificate(
                str(settings.certificate), format=_format_of(settings.certificate)
            )
            await server.load_private_key(
                str(settings.private_key), format=_format_of(settings.private_key)
            )
        except ValueError as err:
            raise ConfigError(f"--private-key {settings.private_key}: {err}") from err
        policies.append(ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt)
        if settings.trusted_clients is not None:
            store = TrustStore([settings.trusted_clients], [])
            await store.load()
            validator = CertificateValidator(
                CertificateValidatorOptions.TRUSTED_VALIDATION
                | CertificateValidatorOptions.PEER_CLIENT,
                store,
            )
            server.set_certificate_validator(LoggedValidator(validator, settings.trusted_clients))
    if settings.anonymous_read_only:
        policies.append(ua.SecurityPolicyType.NoSecurity)
    server.set_security_policy(policies)
    server.set_identity_tokens(tokens)


def _format_of(path: Path) -> str:
    """asyncua guesses a file's format from its name; the content says it (PEM or DER)."""
    return "pem" if path.read_bytes().lstrip().startswith(b"-----BEGIN") else "der"
