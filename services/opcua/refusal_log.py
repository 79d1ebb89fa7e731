"""One log line per refused client: ours, saying who and why; asyncua's own lines of it left out.

asyncua 2.1 logs a refusal two or three times, one of them a traceback: an untrusted
certificate as ``Not trusted certificate used`` with the ``VerificationError`` of its
trust store, then ``sending service fault response: ... (BadCertificateUntrusted)``; an
anonymous session where only user names are offered as ``Rejected active session
UserIdentityToken not supported`` and the fault response again. What is said here instead:

- a client certificate refused: :class:`LoggedValidator` around asyncua's validator, one
  warning naming the certificate's subject and application URI, the status and the reason;
- a session refused at activation: :class:`~.client_sessions.ClientSession` (a token the
  endpoint does not offer, one that does not decrypt); a wrong password or an unknown user:
  :class:`~.server_security.PasswordUsers`, which knows the name.

:func:`quiet_refusals` filters out asyncua's lines of exactly these refusals
(:data:`REFUSALS`), and only those: another service fault is still asyncua's to log.
"""

from __future__ import annotations

import logging
from pathlib import Path

from asyncua import ua
from asyncua.common.utils import ServiceError
from asyncua.crypto.validator import CertificateValidatorMethod
from cryptography import x509

LOG = logging.getLogger(__name__)

#: why a client certificate is refused, by status code
CERTIFICATE_REASONS = {
    ua.StatusCodes.BadCertificateUntrusted: "neither it nor a CA that signed it is in",
    ua.StatusCodes.BadCertificateTimeInvalid: "outside its validity",
    ua.StatusCodes.BadCertificateUriInvalid: "its subjectAltName does not name the client's "
    "application URI",
    ua.StatusCodes.BadCertificateUseNotAllowed: "its key usages do not allow an OPC UA client",
    ua.StatusCodes.BadCertificateInvalid: "not a certificate the server can check",
    ua.StatusCodes.BadCertificateRevoked: "revoked",
}


def status_name(code: int) -> str:
    """A status code's name (``BadCertificateUntrusted``)."""
    return str(ua.StatusCode(ua.UInt32(code)).name)


#: the refusals said here: asyncua's service fault line of these is left out
REFUSALS = frozenset(
    status_name(code)
    for code in (
        *CERTIFICATE_REASONS,
        ua.StatusCodes.BadUserAccessDenied,
        ua.StatusCodes.BadIdentityTokenRejected,
        ua.StatusCodes.BadIdentityTokenInvalid,
    )
)
#: asyncua's loggers and the messages of theirs that a line here replaces
_REPLACED = {
    "asyncuagds.validate": ("Not trusted certificate used",),
    "asyncua.crypto.validator": ("mismatch between application type and certificate",),
    "asyncua.server.internal_session": ("Rejected active session UserIdentityToken",),
}
_FAULT_LOGGER = "asyncua.server.uaprocessor"


class _RefusalFilter(logging.Filter):
    """Leaves out asyncua's records of a refusal said by this module's lines."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.name == _FAULT_LOGGER:
            args = record.args if isinstance(record.args, tuple) else ()
            fault = str(record.msg).startswith("sending service fault")
            return not (fault and REFUSALS & set(args))
        return not str(record.msg).startswith(_REPLACED.get(record.name, ()))


_FILTER = _RefusalFilter()


def quiet_refusals() -> None:
    """Install the filter on asyncua's loggers (once: installing it again changes nothing)."""
    for name in (*_REPLACED, _FAULT_LOGGER):
        logging.getLogger(name).addFilter(_FILTER)


def certificate_name(certificate: x509.Certificate) -> str:
    """``CN=...`` of the subject (its whole subject when it has no common name)."""
    names = certificate.subject.get_attributes_for_oid(x509.NameOID.COMMON_NAME)
    return f"CN={names[0].value!s}" if names else certificate.subject.rfc4514_string()


class LoggedValidator:
    """asyncua's certificate validator, with one line for a certificate it refuses."""

    def __init__(self, validator: CertificateValidatorMethod, trusted_clients: Path) -> None:
        self._validator = validator
        self._trusted_clients = trusted_clients

    async def __call__(
        self, certificate: x509.Certificate, description: ua.ApplicationDescription
    ) -> None:
        try:
            await self._validator(certificate, description)
        except ServiceError as err:
            reason = CERTIFICATE_REASONS.get(err.code, "not accepted")
            if err.code == ua.StatusCodes.BadCertificateUntrusted:
                reason += f" --trusted-clients {self._trusted_clients}"
            LOG.warning(
                "OPC UA client %s refused (%s): certificate %s: %s",
                description.ApplicationUri or "without an application URI",
                status_name(err.code),
                certificate_name(certificate),
                reason,
            )
            raise
