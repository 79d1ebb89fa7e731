"""The station's CAN database (``config/can/station.dbc``), checked against the contract.

Message and signal names are the contract of docs/design.md; ids, layout and
scaling live in the DBC. :class:`StationDatabase` looks every contract message
up once, so a DBC that lacks one fails at start-up with its file named,
and the hot path encodes and decodes through prepared cantools messages. The
final stage's two messages (:data:`STAGE_MESSAGES`) are optional: a DBC
without them is a stop-only station's (``has_stages`` False); so is a
multi-spindle system's ``CycleStart`` (:data:`CYCLE_MESSAGES`, ``has_cycles``),
which a station of more than one spindle needs (:mod:`.spindle_ids`: where each
spindle's frames are).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cantools
import cantools.database

from shared.errors import CanDatabaseError

#: Contract messages and the signals each must carry (docs/design.md, "CAN").
CONTRACT: dict[str, tuple[str, ...]] = {
    "ToolSensors": ("Torque", "Angle", "Counter"),
    "JointSensors": ("Force", "Counter"),
    "ToolStatus": ("RunId", "ToolId", "ProgramId", "State"),
    "StopCommand": ("RunId", "Reason"),
}

#: Messages a tool controller that runs a final stage needs (``StageCommand`` from the
#: station, ``ToolStage`` from the controller): a DBC without them is a stop-only station's,
#: one with them must carry these signals.
STAGE_MESSAGES: dict[str, tuple[str, ...]] = {
    "StageCommand": ("RunId", "Command", "Pulse", "Reason"),
    "ToolStage": ("RunId", "Stage", "Pulses", "Features", "MaxPulses"),
}

#: The message a multi-spindle system sends at each synchronised cycle's start (its sync id):
#: optional, as the final stage's; a station of more than one spindle needs it.
CYCLE_MESSAGES: dict[str, tuple[str, ...]] = {"CycleStart": ("SyncId", "Spindles")}

COUNTER_MODULO = 1 << 16
#: ToolSensors (and JointSensors) are sent at this rate while a run is under way
#: (contract): the Counter is the tool's sample clock, one step per 1/SAMPLE_RATE_HZ s.
SAMPLE_RATE_HZ = 1000.0


class StationDatabase:
    """The contract messages of a DBC, with frame ids and lengths at hand."""

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            database = cantools.database.load_file(str(path))
        except FileNotFoundError as err:
            raise CanDatabaseError(f"{path}: CAN database not found") from err
        except Exception as err:  # cantools raises its own parse errors of many kinds
            raise CanDatabaseError(f"{path}: not a valid DBC: {err}") from err
        if not isinstance(database, cantools.database.can.Database):
            raise CanDatabaseError(f"{path}: not a CAN database")
        self._messages: dict[str, Any] = {}
        for name, signals in CONTRACT.items():
            try:
                message = database.get_message_by_name(name)
            except KeyError as err:
                raise CanDatabaseError(f"{path}: message {name} missing (contract)") from err
            self._messages[name] = _with_signals(path, message, signals)
        present = {m.name for m in database.messages}
        for name, signals in STAGE_MESSAGES.items():
            if name in present:
                message = database.get_message_by_name(name)
                self._messages[name] = _with_signals(path, message, signals)
        stage_names = [name for name in STAGE_MESSAGES if name in self._messages]
        if 0 < len(stage_names) < len(STAGE_MESSAGES):
            lacking = ", ".join(name for name in STAGE_MESSAGES if name not in self._messages)
            raise CanDatabaseError(
                f"{path}: has {', '.join(stage_names)} but not {lacking}: a final stage "
                "needs both (or neither, for a tool that only stops)"
            )
        #: the DBC has the final stage's messages (a tool controller may take StageCommand)
        self.has_stages = bool(stage_names)
        for name, signals in CYCLE_MESSAGES.items():
            if name in present:
                message = database.get_message_by_name(name)
                self._messages[name] = _with_signals(path, message, signals)
        #: the DBC has CycleStart (a multi-spindle system's cycles and their sync ids)
        self.has_cycles = "CycleStart" in self._messages
        self.cycle_start_id: int | None = (
            self._messages["CycleStart"].frame_id if self.has_cycles else None
        )
        self.tool_sensors_id: int = self._messages["ToolSensors"].frame_id
        self.joint_sensors_id: int = self._messages["JointSensors"].frame_id
        self.tool_status_id: int = self._messages["ToolStatus"].frame_id
        self.stop_command_id: int = self._messages["StopCommand"].frame_id
        self.stage_command_id: int | None = (
            self._messages["StageCommand"].frame_id if self.has_stages else None
        )
        self.tool_stage_id: int | None = (
            self._messages["ToolStage"].frame_id if self.has_stages else None
        )
        #: frame id -> (message name, expected data length)
        self.by_id: dict[int, tuple[str, int]] = {
            m.frame_id: (name, m.length) for name, m in self._messages.items()
        }

    def encode(self, name: str, signals: dict[str, float | int]) -> bytes:
        """Data bytes of contract message ``name`` (scaled, range-checked by cantools)."""
        return bytes(self._messages[name].encode(signals, strict=False))

    def decode(self, frame_id: int, data: bytes | bytearray) -> dict[str, float | int]:
        """Physical signal values of a contract frame; raises on bad length or id."""
        name, _ = self.by_id[frame_id]
        decoded: dict[str, float | int] = self._messages[name].decode(
            bytes(data), decode_choices=False
        )
        return decoded

    def decode_named(self, name: str, data: bytes | bytearray) -> dict[str, float | int]:
        """Physical signal values of contract message ``name`` (at whatever id it came: a
        spindle's); raises on a bad length."""
        decoded: dict[str, float | int] = self._messages[name].decode(
            bytes(data), decode_choices=False
        )
        return decoded

    def is_extended(self, name: str) -> bool:
        return bool(self._messages[name].is_extended_frame)

    def length(self, name: str) -> int:
        """The data length of contract message ``name``, bytes."""
        return int(self._messages[name].length)

    def signal_bounds(self, message: str, signal: str) -> tuple[float, float]:
        """(minimum, maximum) physical value of a contract signal.

        The DBC's stated range where it gives one, never wider than what the
        signal's bits can carry at its scale and offset.
        """
        found = self._messages[message].get_signal_by_name(signal)
        raw_low, raw_high = (
            (-(1 << (found.length - 1)), (1 << (found.length - 1)) - 1)
            if found.is_signed
            else (0, (1 << found.length) - 1)
        )
        ends = sorted((raw_low * found.scale + found.offset, raw_high * found.scale + found.offset))
        low = ends[0] if found.minimum is None else max(ends[0], float(found.minimum))
        high = ends[1] if found.maximum is None else min(ends[1], float(found.maximum))
        return float(low), float(high)


def _with_signals(path: Path, message: Any, signals: tuple[str, ...]) -> Any:
    """``message``, once it carries every one of ``signals`` (else one line naming them)."""
    missing = [s for s in signals if s not in {sig.name for sig in message.signals}]
    if missing:
        raise CanDatabaseError(f"{path}: {message.name} lacks signals {', '.join(missing)}")
    return message
