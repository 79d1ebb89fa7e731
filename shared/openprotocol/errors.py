"""The one exception of the Open Protocol codec.

Malformed or out-of-range content of a message raises
:class:`OpenProtocolError`, naming the MID (and revision when known), the
field and what was expected, on one line::

    MID 0061 rev 2, field 'torque final': '00A123' is not a number

It is an :class:`shared.errors.InputError` (data that came from outside and
cannot be used), so a caller can count it and go on with the next message.
"""

from __future__ import annotations

from shared.errors import InputError


class OpenProtocolError(InputError):
    """A message's content is malformed or out of range.

    ``mid`` and ``field`` are kept as attributes so that a caller can count
    refusals per MID and field; ``field == "revision"`` means the revision is
    not implemented (a controller answers that with 0004 error 97).
    """

    def __init__(self, mid: int, field: str, why: str, *, revision: int | None = None) -> None:
        self.mid = mid
        self.field = field
        self.why = why
        self.revision = revision
        where = f"MID {mid:04d}" if revision is None else f"MID {mid:04d} rev {revision}"
        super().__init__(f"{where}, field '{field}': {why}")
