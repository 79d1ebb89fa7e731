"""Salted scrypt password hashes for the OPC UA users file (pure: the standard library only).

A hash is one PHC string (the format passlib and others write for scrypt)::

    $scrypt$ln=14,r=8,p=1$<salt>$<key>

``ln`` is log2 of scrypt's cost N, ``r`` its block size and ``p`` its
parallelism; salt (16 random bytes) and key (32 bytes of ``hashlib.scrypt``)
are base64 without padding. :data:`COST_LN` 14, ``r`` 8, ``p`` 1 is RFC 7914's
figure for interactive logins (16 MiB and about 50 ms a check on one core).

A hash is read only with ``r`` 8, ``p`` 1 and ``ln`` from :data:`MIN_COST_LN` to
:data:`MAX_COST_LN`; any other is refused when the file is read, with what was
expected. Cheaper is a weak hash (an error, not a quiet login); dearer is work
the server would do in its event loop at every login attempt, a user's or an
attacker's (scrypt needs 128 * r * N bytes and time in proportion, p times over).
``r`` and ``p`` are fixed rather than capped: N alone sets the cost, what this
module and the usual tools write (passlib, hashlib's examples) is r 8, p 1, and
the dearest check is then 2^16: 64 MiB and four times the default's time.

:func:`verify` compares in constant time (``hmac.compare_digest``);
:func:`verify_unknown` spends the work of a check on a user who does not exist,
with the cost of :func:`unknown_user_hash` (the dearest hash of the file), so a
refusal of an unknown name takes as long as one of the dearest user's wrong
password.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import hmac
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass

#: log2 of scrypt's N for new hashes
COST_LN = 14
#: the lowest and highest log2 N a hash may have (128 * r * N bytes a check: 2^14 16 MiB,
#: 2^16 64 MiB)
MIN_COST_LN, MAX_COST_LN = 14, 16
#: scrypt's r and p, the only ones a hash may have
BLOCK_SIZE = 8
PARALLELISM = 1
SALT_BYTES = 16
KEY_BYTES = 32
EXPECTED = "$scrypt$ln=N,r=R,p=P$SALT$KEY (write one with `boltwatch opcua-user add`)"

_PHC = re.compile(
    r"\$scrypt\$ln=(?P<ln>[0-9]+),r=(?P<r>[0-9]+),p=(?P<p>[0-9]+)\$(?P<salt>[A-Za-z0-9+/]+)\$"
    r"(?P<key>[A-Za-z0-9+/]+)"
)


class HashFormatError(ValueError):
    """A text that is not a hash this module accepts; the message says what was expected."""


@dataclass(frozen=True, slots=True)
class PasswordHash:
    cost_ln: int
    block_size: int
    parallelism: int
    salt: bytes
    key: bytes

    def text(self) -> str:
        """The PHC string."""
        return (
            f"$scrypt$ln={self.cost_ln},r={self.block_size},p={self.parallelism}"
            f"${_b64(self.salt)}${_b64(self.key)}"
        )


def hash_password(password: str, cost_ln: int = COST_LN) -> PasswordHash:
    """A new hash of ``password`` with a fresh random salt."""
    salt = os.urandom(SALT_BYTES)
    key = _scrypt(password, salt, cost_ln, BLOCK_SIZE, PARALLELISM, KEY_BYTES)
    return PasswordHash(cost_ln, BLOCK_SIZE, PARALLELISM, salt, key)


def parse_hash(text: str) -> PasswordHash:
    """The hash a PHC string holds; HashFormatError saying what was expected."""
    found = _PHC.fullmatch(text)
    if found is None:
        raise HashFormatError(f"expected {EXPECTED}")
    cost_ln, block_size, parallelism = (int(found[k]) for k in ("ln", "r", "p"))
    if not MIN_COST_LN <= cost_ln <= MAX_COST_LN:
        raise HashFormatError(
            f"ln={cost_ln}: expected {MIN_COST_LN} to {MAX_COST_LN} (scrypt's N = 2^ln; "
            "lower is too cheap to guess against, higher too dear for the server to check "
            "at every login)"
        )
    if (block_size, parallelism) != (BLOCK_SIZE, PARALLELISM):
        raise HashFormatError(
            f"r={block_size}, p={parallelism}: expected r={BLOCK_SIZE}, p={PARALLELISM} "
            "(the cost is set by ln alone)"
        )
    try:
        salt, key = _unb64(found["salt"]), _unb64(found["key"])
    except binascii.Error as err:
        raise HashFormatError(f"salt or key is not base64: {err}") from err
    if len(salt) < SALT_BYTES or len(key) < KEY_BYTES:
        raise HashFormatError(
            f"a salt of {len(salt)} bytes and a key of {len(key)}: expected at least "
            f"{SALT_BYTES} and {KEY_BYTES}"
        )
    return PasswordHash(cost_ln, block_size, parallelism, salt, key)


def verify(password: str, stored: PasswordHash) -> bool:
    """Whether ``password`` gives ``stored``'s key, compared in constant time."""
    key = _scrypt(
        password,
        stored.salt,
        stored.cost_ln,
        stored.block_size,
        stored.parallelism,
        len(stored.key),
    )
    return hmac.compare_digest(key, stored.key)


def unknown_user_hash(hashes: Iterable[PasswordHash]) -> PasswordHash:
    """A hash no password matches with the highest cost of ``hashes`` (:data:`COST_LN` when
    there are none), for :func:`verify_unknown`."""
    dearest = max((stored.cost_ln for stored in hashes), default=COST_LN)
    return PasswordHash(dearest, BLOCK_SIZE, PARALLELISM, b"\0" * SALT_BYTES, b"\0" * KEY_BYTES)


def verify_unknown(password: str, unknown: PasswordHash) -> bool:
    """False, after the work of checking ``password`` against ``unknown`` (a user that does
    not exist; ``unknown`` from :func:`unknown_user_hash` of the known users' hashes)."""
    verify(password, unknown)
    return False


def _scrypt(password: str, salt: bytes, cost_ln: int, r: int, p: int, length: int) -> bytes:
    n = 1 << cost_ln
    # scrypt's memory: 128 * r * N for its table, 128 * r * p for its blocks; OpenSSL
    # refuses more than maxmem (32 MiB unless given)
    maxmem = 128 * r * (n + p) + (1 << 20)
    return hashlib.scrypt(
        password.encode("utf-8"), salt=salt, n=n, r=r, p=p, maxmem=maxmem, dklen=length
    )


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii").rstrip("=")


def _unb64(text: str) -> bytes:
    return base64.b64decode(text + "=" * (-len(text) % 4), validate=True)
