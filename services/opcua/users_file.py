"""The OPC UA users file (``--users FILE``): user names, their password hashes and roles.

::

    # written by `boltwatch opcua-user`
    [users.line-mes]
    password_hash = "$scrypt$ln=14,r=8,p=1$...$..."
    role = "reader"

One table per user under ``users``; the key is the user name an OPC UA client
gives (1 to 64 characters, no control characters). ``password_hash`` is a
salted scrypt hash (:mod:`.password_hashes`), never the password. ``role`` is
``reader`` (reads, and calls ResultManagement's four methods) or ``operator`` (also
acknowledges, confirms and comments on the alerts' conditions: a SCADA's user).
Nothing in the address space is writable by either.

:func:`read_users` fails with one line naming the file, the key and what was
expected; :func:`write_users` replaces the file whole (a temporary file made
0600, renamed), so a crash leaves the old file or the new one.
"""

from __future__ import annotations

import re
import stat
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, StringConstraints, field_validator

from services.opcua.password_hashes import HashFormatError, PasswordHash, parse_hash
from shared.config import StrictModel, dumps, read_toml, validate
from shared.files import write_text_atomically

Role = Literal["reader", "operator"]
READER: Role = "reader"
#: the role that may acknowledge, confirm and comment on conditions
OPERATOR: Role = "operator"
NAME_PATTERN = r"^[^\x00-\x1f\x7f]+$"
NAME_MAX_CHARACTERS = 64
HEADER = (
    "# OPC UA users of `boltwatch serve opcua --users`, written by `boltwatch opcua-user`.\n"
    "# password_hash: salted scrypt, never the password. role: reader, or operator (also\n"
    "# acknowledges the alerts' conditions).\n\n"
)

UserName = Annotated[
    str, StringConstraints(min_length=1, max_length=NAME_MAX_CHARACTERS, pattern=NAME_PATTERN)
]


class _UserEntry(StrictModel):
    password_hash: str = Field(description="$scrypt$ln=N,r=R,p=P$SALT$KEY")
    role: Role = READER

    @field_validator("password_hash")
    @classmethod
    def _a_hash(cls, text: str) -> str:
        try:
            parse_hash(text)
        except HashFormatError as err:
            raise ValueError(str(err)) from err
        return text


class _UsersFile(StrictModel):
    users: dict[UserName, _UserEntry] = Field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class OpcuaUser:
    name: str
    password_hash: PasswordHash
    role: Role = READER


def read_users(path: Path) -> dict[str, OpcuaUser]:
    """The users of ``path`` by name; ConfigError naming the file and key when it is bad."""
    document = validate(_UsersFile, read_toml(path), path)
    return {
        name: OpcuaUser(name, parse_hash(entry.password_hash), entry.role)
        for name, entry in document.users.items()
    }


def write_users(path: Path, users: Mapping[str, OpcuaUser]) -> None:
    """Replace ``path`` by ``users`` (in name order), whole or not at all, mode 0600."""
    document = {
        "users": {
            name: {"password_hash": user.password_hash.text(), "role": user.role}
            for name, user in sorted(users.items())
        }
    }
    write_text_atomically(path, HEADER + (dumps(document) if users else ""))


def valid_user_name(name: str) -> bool:
    """Whether the file accepts ``name`` as a user name."""
    return len(name) <= NAME_MAX_CHARACTERS and re.fullmatch(NAME_PATTERN, name) is not None


def others_may_read(path: Path) -> bool:
    """Whether anyone on the host may read ``path`` (its mode has o+r)."""
    return bool(path.stat().st_mode & stat.S_IROTH)
