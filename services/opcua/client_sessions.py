"""The server's sessions: who calls a method, and one line for an activation refused.

asyncua's server makes a session for each client through its internal server's
``create_session``; :func:`use_client_sessions` has it make a :class:`ClientSession`,
asyncua's ``InternalSession`` with three additions:

- each Call request runs with its session in :data:`CALLER` (a context variable of the
  request's task): an ``async`` method callback knows who calls it (a condition's
  Acknowledge records the user, ConditionRefresh checks that the subscription is the
  caller's). A callback that is not a coroutine function runs in asyncua's thread pool,
  where the variable is not set;
- the client's application URI from CreateSession (:attr:`ClientSession.client_uri`);
- an activation refused (a user token the endpoint does not offer: an anonymous session
  where user names are asked; a token that does not decrypt) leaves one warning line
  (:mod:`.refusal_log` leaves asyncua's out). A wrong password or an unknown user is said
  by the user manager, which knows the name.
"""

from __future__ import annotations

import logging
from contextvars import ContextVar
from typing import Any

from asyncua import Server, ua
from asyncua.common.utils import ServiceError
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.internal_session import InternalSession

from services.opcua.refusal_log import status_name

LOG = logging.getLogger(__name__)

ANONYMOUS = User(role=UserRole.Anonymous)
#: the session of the Call request being answered (None outside one)
CALLER: ContextVar[ClientSession | None] = ContextVar("opcua_caller", default=None)


class ClientSession(InternalSession):
    """asyncua's session of a client, known to the method callbacks it calls."""

    client_uri: str = ""

    @property
    def user_name(self) -> str:
        """The session's user name ("" for an anonymous session)."""
        return str(getattr(self.user, "name", None) or "")

    async def create_session(
        self, params: ua.CreateSessionParameters, sockname: tuple[str, int] | None = None
    ) -> ua.CreateSessionResult:
        description = params.ClientDescription
        self.client_uri = str(description.ApplicationUri or "") if description else ""
        return await super().create_session(params, sockname)

    def activate_session(
        self, params: ua.ActivateSessionParameters, peer_certificate: bytes | None
    ) -> ua.ActivateSessionResult:
        try:
            return super().activate_session(params, peer_certificate)
        except ServiceError as err:
            if err.code != ua.StatusCodes.BadUserAccessDenied:  # said with the user's name
                rejected = err.code == ua.StatusCodes.BadIdentityTokenRejected
                LOG.warning(
                    "OPC UA session of %s refused (%s): %s, %s",
                    self.client_uri or "a client without an application URI",
                    status_name(err.code),
                    _token_said(params.UserIdentityToken),
                    "a token the endpoint does not offer" if rejected else "not readable",
                )
            raise

    async def call(self, params: list[ua.CallMethodRequest]) -> list[ua.CallMethodResult]:
        token = CALLER.set(self)
        try:
            return await super().call(params)
        finally:
            CALLER.reset(token)


def _token_said(token: Any) -> str:
    """The session's user token in words."""
    if isinstance(token, ua.UserNameIdentityToken):
        return f"user {token.UserName!r}"
    if isinstance(token, ua.X509IdentityToken):
        return "a user certificate"
    if isinstance(token, ua.IssuedIdentityToken):
        return "an issued token"
    return "anonymous"


def use_client_sessions(server: Server) -> None:
    """Have ``server`` make a :class:`ClientSession` for each client."""
    iserver = server.iserver

    def create_session(name: str, user: User = ANONYMOUS, external: bool = False) -> ClientSession:
        return ClientSession(
            iserver, iserver.aspace, iserver.subscription_service, name, user, external
        )

    iserver.create_session = create_session  # type: ignore[method-assign]
