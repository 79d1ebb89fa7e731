"""``boltwatch opcua-user``: the users file of ``boltwatch serve opcua --users``.

::

    boltwatch opcua-user add NAME [--role reader|operator] --users FILE
                                                    a user, or a user's new password
    boltwatch opcua-user remove NAME --users FILE
    boltwatch opcua-user list --users FILE          the names and their roles

``add`` reads the password from the terminal (asked twice, not echoed) or, when
standard input is not a terminal, its first line (``printf '%s\\n' "$PW" |
boltwatch opcua-user add line-mes --users users.toml``). It writes a salted
scrypt hash, never the password, and makes the file if it is missing; the file
is replaced whole, mode 0600. Format: :mod:`services.opcua.users_file`.
"""

from __future__ import annotations

import argparse
import getpass
import sys
from pathlib import Path

from shared.errors import InputError

NAME = "opcua-user"
HELP = "add, remove or list the users of the OPC UA server's users file (--users)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "The users file of 'boltwatch serve opcua --users FILE': user names with salted "
        "scrypt password hashes and a role (reader: reads and asks for results; operator: "
        "also acknowledges, confirms and comments on the alerts' conditions). "
        "'add NAME' asks the password twice on a terminal, or reads the first line of "
        "standard input; it adds the user or replaces its password, making the file (mode "
        "0600) if it is missing. The server reads the file at start: restart it after a change."
    )
    parser.add_argument("action", choices=["add", "remove", "list"], help="what to do")
    parser.add_argument("name", nargs="?", default=None, help="the user name (add, remove)")
    parser.add_argument(
        "--users", type=Path, required=True, metavar="FILE", help="the users file (TOML)"
    )
    parser.add_argument(
        "--role",
        choices=["reader", "operator"],
        default=None,
        help="add: the user's role (default: a new user's reader, a known user's its own)",
    )


def run(args: argparse.Namespace) -> int:
    from services.opcua.password_hashes import hash_password
    from services.opcua.users_file import (
        READER,
        OpcuaUser,
        read_users,
        valid_user_name,
        write_users,
    )

    if args.action == "list":
        for user in read_users(args.users).values():
            print(f"{user.name}\t{user.role}")
        return 0
    if args.name is None:
        raise InputError(f"{args.action} needs a user name: opcua-user {args.action} NAME")
    users = read_users(args.users) if args.action == "remove" or args.users.exists() else {}
    if args.action == "remove":
        if users.pop(args.name, None) is None:
            raise InputError(f"{args.users}: no user {args.name!r}")
        write_users(args.users, users)
        return 0
    if not valid_user_name(args.name):
        raise InputError(f"user name {args.name!r}: expected 1 to 64 characters, no control ones")
    if not args.users.parent.is_dir():  # before the password is asked
        raise InputError(f"{args.users}: folder {args.users.parent} does not exist")
    known = users.get(args.name)
    role = args.role or (known.role if known is not None else READER)
    users[args.name] = OpcuaUser(args.name, hash_password(_password()), role)
    write_users(args.users, users)
    article = "an" if role == "operator" else "a"
    if known is None:
        said = f"added, {article} {role}"
    else:
        said = "new password" + ("" if role == known.role else f", {article} {role}")
    print(f"{args.users}: {args.name}: {said}")
    return 0


def _password() -> str:
    """From the terminal (twice) or standard input's first line; InputError when empty."""
    if sys.stdin.isatty():
        password = getpass.getpass("password: ")
        if getpass.getpass("again: ") != password:
            raise InputError("the two passwords differ")
    else:
        password = sys.stdin.readline().removesuffix("\n").removesuffix("\r")
    if not password:
        raise InputError("an empty password (give one on standard input or the terminal)")
    return password
