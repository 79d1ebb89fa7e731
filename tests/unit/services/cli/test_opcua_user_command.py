"""``boltwatch opcua-user``: a user added with its password from standard input, its
password replaced, listed, removed; what it refuses, in one line each."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from services.cli.main import main
from services.opcua.password_hashes import verify
from services.opcua.users_file import read_users


def _run(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    *arguments: str,
    stdin: str = "",
) -> tuple[int, str, str]:
    monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
    status = main(["opcua-user", *arguments])
    out = capsys.readouterr()
    return status, out.out, out.err


def test_add_replace_list_and_remove_users(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "opcua" / "users.toml"
    path.parent.mkdir()
    assert _run(capsys, monkeypatch, "add", "line-mes", "--users", str(path), stdin="s3cret\n") == (
        0,
        f"{path}: line-mes: added, a reader\n",
        "",
    )
    assert _run(capsys, monkeypatch, "add", "plc", "--users", str(path), stdin="other\r\n")[0] == 0
    status, out, _ = _run(capsys, monkeypatch, "add", "line-mes", "--users", str(path), stdin="new")
    assert (status, out) == (0, f"{path}: line-mes: new password\n")
    users = read_users(path)
    assert verify("new", users["line-mes"].password_hash)
    assert verify("other", users["plc"].password_hash)
    assert "new" not in path.read_text() and "other" not in path.read_text()
    assert _run(capsys, monkeypatch, "list", "--users", str(path)) == (
        0,
        "line-mes\treader\nplc\treader\n",
        "",
    )
    assert _run(capsys, monkeypatch, "remove", "plc", "--users", str(path))[0] == 0
    assert list(read_users(path)) == ["line-mes"]


@pytest.mark.parametrize(
    ("arguments", "stdin", "expected"),
    [
        (("add", "a"), "\n", "an empty password"),
        (("add", "a\tb"), "pw\n", "user name 'a\\tb': expected 1 to 64 characters"),
        (("add",), "pw\n", "add needs a user name"),
        (("remove", "nobody"), "", "no user 'nobody'"),
    ],
    ids=["empty password", "bad name", "no name", "unknown user"],
)
def test_what_it_refuses(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    arguments: tuple[str, ...],
    stdin: str,
    expected: str,
) -> None:
    path = tmp_path / "users.toml"
    path.write_text("")
    status, _, err = _run(capsys, monkeypatch, *arguments, "--users", str(path), stdin=stdin)
    assert status == 2
    assert err.startswith("boltwatch opcua-user: ") and expected in err, err
    assert path.read_text() == ""


def test_an_operator_may_be_added_and_keeps_its_role_with_a_new_password(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """An operator also acknowledges and confirms the alerts' conditions (a SCADA's user)."""
    path = tmp_path / "users.toml"
    added = _run(
        capsys,
        monkeypatch,
        "add",
        "scada",
        "--role",
        "operator",
        "--users",
        str(path),
        stdin="pw\n",
    )
    assert added == (0, f"{path}: scada: added, an operator\n", "")
    assert _run(capsys, monkeypatch, "add", "scada", "--users", str(path), stdin="new\n")[0] == 0
    assert read_users(path)["scada"].role == "operator"
    demoted = _run(
        capsys, monkeypatch, "add", "scada", "--role", "reader", "--users", str(path), stdin="x\n"
    )
    assert demoted == (0, f"{path}: scada: new password, a reader\n", "")
    assert _run(capsys, monkeypatch, "list", "--users", str(path))[1] == "scada\treader\n"
