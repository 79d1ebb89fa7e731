"""Classify and decode one CAN frame against the station DBC (pure, no bus).

Returns a small typed record per contract frame, with the spindle it is of (1
on a single-spindle station; a multi-spindle station's spindle k sends at the
DBC's ids shifted by its stride: :class:`~shared.contract.SpindleIds`), or a
:class:`Rejected` that says why the frame is not usable. Nothing here raises
on bad traffic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.contract import SpindleIds

RejectReason = Literal["error_frame", "unknown_id", "wrong_length", "decode_error", "remote_frame"]


@dataclass(frozen=True, slots=True)
class ToolSensorsFrame:
    counter: int
    torque_nm: float
    angle_deg: float
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class JointSensorsFrame:
    counter: int
    force_n: float
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class ToolStatusFrame:
    run_id: int
    tool_id: int
    program_id: int
    state: int
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class StopCommandFrame:
    run_id: int
    reason: int
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class ToolStageFrame:
    """What a tool controller that runs a final stage is doing (ToolStage)."""

    run_id: int
    stage: int
    pulses: int
    features: int
    max_pulses: int
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class StageCommandFrame:
    """A StageCommand on the bus (another node's: the station sends its own)."""

    run_id: int
    command: int
    spindle: int = 1


@dataclass(frozen=True, slots=True)
class CycleStartFrame:
    """A multi-spindle system's cycle starts (CycleStart): its sync id."""

    sync_id: int
    spindles: int


@dataclass(frozen=True, slots=True)
class Rejected:
    reason: RejectReason


DecodedFrame = (
    ToolSensorsFrame
    | JointSensorsFrame
    | ToolStatusFrame
    | ToolStageFrame
    | StopCommandFrame
    | StageCommandFrame
    | CycleStartFrame
    | Rejected
)


class FrameDecoder:
    """Decode frames of the contract messages; everything else is a Rejected."""

    def __init__(self, spindle_ids: SpindleIds) -> None:
        self._database = spindle_ids.database
        self._by_id = spindle_ids.by_id

    def decode(
        self,
        arbitration_id: int,
        data: bytes | bytearray,
        *,
        is_error_frame: bool = False,
        is_remote_frame: bool = False,
    ) -> DecodedFrame:
        if is_error_frame:
            return Rejected("error_frame")
        if is_remote_frame:
            return Rejected("remote_frame")
        known = self._by_id.get(arbitration_id)
        if known is None:
            return Rejected("unknown_id")
        name, spindle = known.name, known.spindle
        if len(data) != known.length:
            return Rejected("wrong_length")
        try:
            signals = self._database.decode_named(name, data)
        except Exception:  # cantools raises several types on bad payloads
            return Rejected("decode_error")
        if name == "ToolSensors":
            return ToolSensorsFrame(
                int(signals["Counter"]), float(signals["Torque"]), float(signals["Angle"]), spindle
            )
        if name == "JointSensors":
            return JointSensorsFrame(int(signals["Counter"]), float(signals["Force"]), spindle)
        if name == "ToolStatus":
            return ToolStatusFrame(
                int(signals["RunId"]),
                int(signals["ToolId"]),
                int(signals["ProgramId"]),
                int(signals["State"]),
                spindle,
            )
        if name == "ToolStage":
            return ToolStageFrame(
                int(signals["RunId"]),
                int(signals["Stage"]),
                int(signals["Pulses"]),
                int(signals["Features"]),
                int(signals["MaxPulses"]),
                spindle,
            )
        if name == "StageCommand":
            return StageCommandFrame(int(signals["RunId"]), int(signals["Command"]), spindle)
        if name == "CycleStart":
            return CycleStartFrame(int(signals["SyncId"]), int(signals["Spindles"]))
        return StopCommandFrame(int(signals["RunId"]), int(signals["Reason"]), spindle)
