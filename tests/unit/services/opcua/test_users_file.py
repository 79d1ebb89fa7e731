"""The OPC UA users file and its password hashes: written and read back, checked against
a hash someone else wrote (RFC 7914's scrypt test vector), and each bad file refused with
one line naming the file, the key and what was expected."""

from __future__ import annotations

import stat
from dataclasses import replace
from pathlib import Path

import pytest

from services.opcua.password_hashes import (
    COST_LN,
    MAX_COST_LN,
    HashFormatError,
    PasswordHash,
    hash_password,
    parse_hash,
    unknown_user_hash,
    verify,
    verify_unknown,
)
from services.opcua.server_security import PasswordUsers, SecuritySettings
from services.opcua.users_file import OpcuaUser, others_may_read, read_users, write_users
from shared.errors import ConfigError

#: RFC 7914, section 12: scrypt("pleaseletmein", "SodiumChloride", N=16384, r=8, p=1), 64 bytes
RFC_KEY = bytes.fromhex(
    "7023bdcb3afd7348461c06cd81fd38ebfda8fbba904f8e3ea9b543f6545da1f2"
    "d5432955613f0fcf62d49705242a9af9e61e85dc0d651e40dfcf017b45575887"
)


def test_a_hash_of_rfc_7914_verifies_its_password_only() -> None:
    stored = PasswordHash(14, 8, 1, b"SodiumChloride", RFC_KEY)
    assert verify("pleaseletmein", stored)
    assert not verify("pleaseletmein ", stored)
    assert not verify_unknown("pleaseletmein", unknown_user_hash([stored]))


def test_a_new_hash_is_salted_and_reads_back() -> None:
    first, second = hash_password("same"), hash_password("same")
    assert first.salt != second.salt and first.key != second.key
    assert parse_hash(first.text()) == first
    assert verify("same", parse_hash(first.text()))
    assert not verify("Same", first)


def test_the_file_written_reads_back_and_only_its_owner_reads_it(tmp_path: Path) -> None:
    path = tmp_path / "users.toml"
    users = {name: OpcuaUser(name, hash_password(name)) for name in ("line-mes", "plc 7")}
    write_users(path, users)
    assert read_users(path) == users
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert not others_may_read(path)
    path.chmod(0o644)
    assert others_may_read(path)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("plain", "expected $scrypt$ln=N,r=R,p=P$SALT$KEY"),
        ("$scrypt$ln=10,r=8,p=1$c2FsdHNhbHRzYWx0c2FsdA$a2V5", "ln=10: expected 14 to 16"),
        # 4 GiB and minutes of the server's loop a login, with r 32 and p 16
        ("$scrypt$ln=20,r=8,p=1$c2FsdA$a2V5", "ln=20: expected 14 to 16"),
        ("$scrypt$ln=14,r=8,p=1$c2FsdA$a2V5", "a salt of 4 bytes and a key of 3"),
        ("$scrypt$ln=14,r=32,p=1$c2FsdA$a2V5", "r=32, p=1: expected r=8, p=1"),
        ("$scrypt$ln=14,r=8,p=16$c2FsdA$a2V5", "r=8, p=16: expected r=8, p=1"),
        ("$scrypt$ln=１４,r=8,p=1$c2FsdA$a2V5", "expected $scrypt$ln=N"),  # fullwidth digits
    ],
)
def test_a_hash_that_is_not_one_says_what_was_expected(text: str, expected: str) -> None:
    with pytest.raises(HashFormatError, match=expected.replace("$", r"\$")):
        parse_hash(text)


GOOD = hash_password("x").text()
DEAR = GOOD.replace(",p=1$", ",p=2$")


def test_an_unknown_name_costs_the_dearest_hash_of_the_file() -> None:
    """A name not in the file is checked against a hash of the file's highest cost, so
    the refusal does not come sooner than the dearest user's."""
    cheap, dear = parse_hash(GOOD), replace(parse_hash(GOOD), cost_ln=MAX_COST_LN)
    users = {"a": OpcuaUser("a", cheap), "b": OpcuaUser("b", dear), "c": OpcuaUser("c", cheap)}
    assert PasswordUsers(users).unknown_hash.cost_ln == MAX_COST_LN
    assert PasswordUsers({"a": OpcuaUser("a", cheap)}).unknown_hash.cost_ln == cheap.cost_ln
    assert unknown_user_hash([]).cost_ln == COST_LN


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("[users.a\n", "not valid TOML"),
        ("[users.a]\nrole = 'reader'\n", "users.a.password_hash: Field required"),
        (f"[users.a]\npassword_hash = '{GOOD}'\npassword = 'x'\n", "users.a.password: unknown"),
        (f"[users.a]\npassword_hash = '{GOOD}'\nrole = 'admin'\n", "users.a.role: Input should"),
        (f"[users.\"a\\u0007\"]\npassword_hash = '{GOOD}'\n", "users.a\x07.[key]: String should"),
        ("[users.a]\npassword_hash = 'plain'\n", "users.a.password_hash: expected $scrypt$"),
        (f"[users.a]\npassword_hash = '{DEAR}'\n", "users.a.password_hash: r=8, p=2: expected"),
        ("[user.a]\n", "user: unknown key; expected one of: users"),
    ],
    ids=[
        "not TOML",
        "no hash",
        "a password",
        "a role",
        "a name",
        "a plain hash",
        "a dear hash",
        "a table",
    ],
)
def test_a_bad_users_file_names_the_file_and_the_key(
    tmp_path: Path, text: str, expected: str
) -> None:
    path = tmp_path / "users.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as raised:
        read_users(path)
    assert str(raised.value).startswith(f"{path}: "), raised.value
    assert expected in str(raised.value), raised.value


def test_the_server_refuses_a_users_file_without_users_or_with_anonymous_sessions(
    tmp_path: Path,
) -> None:
    path = tmp_path / "users.toml"
    write_users(path, {})
    certificate = tmp_path / "server.pem"
    certificate.write_text("not read by check")
    settings = SecuritySettings(certificate, certificate, tmp_path, path)
    with pytest.raises(ConfigError, match=r"--users .*users.toml: users: no user \(add one"):
        settings.check()
    for certificates in (certificate, None):
        both = SecuritySettings(certificates, certificates, None, path, anonymous_read_only=True)
        with pytest.raises(ConfigError, match="give --users or --anonymous-read-only, not both"):
            both.check()
    default = SecuritySettings(certificate, certificate, tmp_path, None)
    with pytest.raises(ConfigError, match=r"give --users \(Basic256Sha256 sign and encrypt"):
        default.check()
