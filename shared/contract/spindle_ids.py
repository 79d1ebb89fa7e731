"""Where each spindle's frames are on a multi-spindle station's CAN bus (pure).

A multi-spindle system is one station with N spindles on one bus. The DBC
keeps the contract's message and signal names once; spindle k (1..N) sends
and takes each of them at the DBC's id plus ``(k - 1) * stride`` (the station
file's ``[can] spindle_id_stride``, 2 by default), with its own ``Counter``:
``ToolSensors``, ``JointSensors``, ``ToolStatus``, ``ToolStage`` from it,
``StopCommand`` and ``StageCommand`` to it. Spindle 1's ids are the DBC's, so
a single-spindle station's bus is unchanged. ``CycleStart`` (the controller's,
at each cycle's start: its sync id) is one message of the station, at the
DBC's id for every spindle.

:class:`SpindleIds` lays the ids out once and refuses (``CanDatabaseError``)
a layout a bus cannot carry: two frames at one id (a stride that lands one
spindle's message on another's, or on ``CycleStart``), an id beyond its
format (11 bits standard, 29 extended), or more than one spindle with no
``CycleStart`` in the DBC. ``docs/reference/can-and-trace.md`` says it for a
third party's controller.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract.can_database import CYCLE_MESSAGES, StationDatabase
from shared.errors import CanDatabaseError

#: the largest id of each frame format
STANDARD_ID_MAX = 0x7FF
EXTENDED_ID_MAX = 0x1FFF_FFFF


@dataclass(frozen=True, slots=True)
class SpindleFrame:
    """What a frame id is on the station's bus."""

    name: str  # the contract message
    length: int  # its data length, bytes
    spindle: int  # 1..N (CycleStart: 1, the station's own)


class SpindleIds:
    """The frame ids of each spindle of a station."""

    def __init__(self, database: StationDatabase, spindles: int = 1, stride: int = 2) -> None:
        if spindles < 1:
            raise CanDatabaseError(f"a station has at least one spindle (got {spindles})")
        if spindles > 1 and not database.has_cycles:
            raise CanDatabaseError(
                f"{database.path}: {spindles} spindles need the DBC's CycleStart (SyncId, "
                "Spindles): the controller's sync id of each cycle"
            )
        self.database = database
        self.spindles = spindles
        self.stride = stride
        #: frame id -> what it is, for every frame of every spindle
        self.by_id: dict[int, SpindleFrame] = {}
        for frame_id, (name, length) in database.by_id.items():
            copies = 1 if name in CYCLE_MESSAGES else spindles
            for spindle in range(1, copies + 1):
                self._place(frame_id + (spindle - 1) * stride, SpindleFrame(name, length, spindle))

    def _place(self, frame_id: int, frame: SpindleFrame) -> None:
        highest = EXTENDED_ID_MAX if self.database.is_extended(frame.name) else STANDARD_ID_MAX
        if frame_id > highest:
            raise CanDatabaseError(
                f"spindle {frame.spindle}'s {frame.name} would be at id {frame_id:#x}, beyond "
                f"{highest:#x} (stride {self.stride}, {self.spindles} spindles)"
            )
        taken = self.by_id.get(frame_id)
        if taken is not None:
            raise CanDatabaseError(
                f"spindle {frame.spindle}'s {frame.name} and spindle {taken.spindle}'s "
                f"{taken.name} would share id {frame_id:#x} (stride {self.stride}, "
                f"{self.spindles} spindles): choose a stride that keeps them apart"
            )
        self.by_id[frame_id] = frame

    def offset(self, spindle: int) -> int:
        """What spindle ``spindle``'s ids add to the DBC's."""
        return (spindle - 1) * self.stride
