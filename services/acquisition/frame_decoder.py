"""Classify and decode one CAN frame against the station DBC (pure, no bus).

Returns a small typed record per contract frame, or a :class:`Rejected` that
says why the frame is not usable. Nothing here raises on bad traffic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.contract import StationDatabase

RejectReason = Literal["error_frame", "unknown_id", "wrong_length", "decode_error", "remote_frame"]


@dataclass(frozen=True, slots=True)
class ToolSensorsFrame:
    counter: int
    torque_nm: float
    angle_deg: float


@dataclass(frozen=True, slots=True)
class JointSensorsFrame:
    counter: int
    force_n: float


@dataclass(frozen=True, slots=True)
class ToolStatusFrame:
    run_id: int
    tool_id: int
    program_id: int
    state: int


@dataclass(frozen=True, slots=True)
class StopCommandFrame:
    run_id: int
    reason: int


@dataclass(frozen=True, slots=True)
class ToolStageFrame:
    """What a tool controller that runs a final stage is doing (ToolStage)."""

    run_id: int
    stage: int
    pulses: int
    features: int
    max_pulses: int


@dataclass(frozen=True, slots=True)
class StageCommandFrame:
    """A StageCommand on the bus (another node's: the station sends its own)."""

    run_id: int
    command: int


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
    | Rejected
)


class FrameDecoder:
    """Decode frames of the contract messages; everything else is a Rejected."""

    def __init__(self, database: StationDatabase) -> None:
        self._database = database

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
        known = self._database.by_id.get(arbitration_id)
        if known is None:
            return Rejected("unknown_id")
        name, length = known
        if len(data) != length:
            return Rejected("wrong_length")
        try:
            signals = self._database.decode(arbitration_id, data)
        except Exception:  # cantools raises several types on bad payloads
            return Rejected("decode_error")
        if name == "ToolSensors":
            return ToolSensorsFrame(
                int(signals["Counter"]), float(signals["Torque"]), float(signals["Angle"])
            )
        if name == "JointSensors":
            return JointSensorsFrame(int(signals["Counter"]), float(signals["Force"]))
        if name == "ToolStatus":
            return ToolStatusFrame(
                int(signals["RunId"]),
                int(signals["ToolId"]),
                int(signals["ProgramId"]),
                int(signals["State"]),
            )
        if name == "ToolStage":
            return ToolStageFrame(
                int(signals["RunId"]),
                int(signals["Stage"]),
                int(signals["Pulses"]),
                int(signals["Features"]),
                int(signals["MaxPulses"]),
            )
        if name == "StageCommand":
            return StageCommandFrame(int(signals["RunId"]), int(signals["Command"]))
        return StopCommandFrame(int(signals["RunId"]), int(signals["Reason"]))
