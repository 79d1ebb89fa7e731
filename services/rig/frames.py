"""The rig's CAN frames, encoded through the station's DBC (contract names only).

The tool controller sends ToolSensors and ToolStatus (and, when it runs a
final stage, ToolStage), the force sensor node JointSensors; both listen for
StopCommand (the controller for StageCommand too). Ids, layout and scaling come from
:class:`~shared.contract.can_database.StationDatabase`, never from this file. A
reading beyond what its signal can carry is sent at the end of the range, as
a real transducer saturates at full scale (the predictor counts it as
``saturated``); the station file's limits are checked against the range at
start (a limit beyond it is a configuration error).
"""

from __future__ import annotations

import can

from shared.contract import (
    COUNTER_MODULO,
    FEATURE_STAGES,
    SensorRange,
    StageCommandCode,
    StationDatabase,
    ToolRunState,
    ToolStageCode,
)


class RigFrames:
    """Builds the rig's outgoing frames and reads incoming StopCommands (of one spindle: a
    multi-spindle system's spindle k at the DBC's ids plus ``id_offset``, (k - 1) times the
    station's stride: :class:`~shared.contract.SpindleIds`)."""

    def __init__(self, database: StationDatabase, id_offset: int = 0) -> None:
        self._database = database
        self._offset = id_offset
        sensor_range = SensorRange.of_database(database)
        self._torque_nm = sensor_range.torque_nm
        self._angle_deg = sensor_range.angle_deg
        self._force_n = sensor_range.force_n
        names = ["ToolSensors", "JointSensors", "ToolStatus"]
        if database.has_stages:
            names.append("ToolStage")
        self._extended = {name: database.is_extended(name) for name in names}
        #: the DBC has the final stage's messages (the rig may run one)
        self.has_stages = database.has_stages

    @property
    def database(self) -> StationDatabase:
        return self._database

    def _message(self, name: str, frame_id: int, signals: dict[str, float | int]) -> can.Message:
        return can.Message(
            arbitration_id=frame_id + self._offset,
            data=self._database.encode(name, signals),
            is_extended_id=self._extended[name],
        )

    def tool_sensors(self, torque_nm: float, angle_deg: float, counter: int) -> can.Message:
        return self._message(
            "ToolSensors",
            self._database.tool_sensors_id,
            {
                "Torque": _saturated(torque_nm, self._torque_nm),
                "Angle": _saturated(angle_deg, self._angle_deg),
                "Counter": counter % COUNTER_MODULO,
            },
        )

    def joint_sensors(self, force_n: float, counter: int) -> can.Message:
        return self._message(
            "JointSensors",
            self._database.joint_sensors_id,
            {"Force": _saturated(force_n, self._force_n), "Counter": counter % COUNTER_MODULO},
        )

    def tool_status(
        self, run_id: int, tool_id: int, program_id: int, state: ToolRunState
    ) -> can.Message:
        return self._message(
            "ToolStatus",
            self._database.tool_status_id,
            {"RunId": run_id, "ToolId": tool_id, "ProgramId": program_id, "State": int(state)},
        )

    def tool_stage(
        self, run_id: int, stage: ToolStageCode, pulses: int, max_pulses: int
    ) -> can.Message:
        """ToolStage of a controller that takes StageCommand (Features bit 0 set)."""
        tool_stage_id = self._database.tool_stage_id
        assert tool_stage_id is not None  # only with a DBC that has it (has_stages)
        return self._message(
            "ToolStage",
            tool_stage_id,
            {
                "RunId": run_id,
                "Stage": int(stage),
                "Pulses": pulses,
                "Features": FEATURE_STAGES,
                "MaxPulses": max_pulses,
            },
        )

    def cycle_start(self, sync_id: int, spindles: int) -> can.Message:
        """CycleStart of a multi-spindle system: the station's own, at the DBC's id."""
        frame_id = self._database.cycle_start_id
        assert frame_id is not None  # only with a DBC that has it (has_cycles)
        return can.Message(
            arbitration_id=frame_id,
            data=self._database.encode("CycleStart", {"SyncId": sync_id, "Spindles": spindles}),
            is_extended_id=self._database.is_extended("CycleStart"),
        )

    def stage_command(self, message: can.Message) -> tuple[int, StageCommandCode] | None:
        """(RunId, Command) of a StageCommand frame; None for any other or malformed frame,
        and for a command this controller does not know."""
        frame_id = self._database.stage_command_id
        if frame_id is None or message.arbitration_id != frame_id + self._offset:
            return None
        if message.is_error_frame:
            return None
        try:
            signals = self._database.decode_named("StageCommand", message.data)
            return int(signals["RunId"]), StageCommandCode(int(signals["Command"]))
        except Exception:  # cantools raises several kinds; ValueError for an unknown command
            return None

    def stop_command_run_id(self, message: can.Message) -> int | None:
        """The RunId of a StopCommand frame; None for any other (or malformed) frame."""
        frame_id = self._database.stop_command_id + self._offset
        if message.arbitration_id != frame_id or message.is_error_frame:
            return None
        try:
            signals = self._database.decode_named("StopCommand", message.data)
        except Exception:  # cantools raises several kinds on a short or garbled frame
            return None
        return int(signals["RunId"])


def _saturated(value: float, bounds: tuple[float, float]) -> float:
    """``value`` held to the signal's range, as a transducer at full scale."""
    low, high = bounds
    return min(max(value, low), high)
