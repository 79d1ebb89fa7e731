"""The CAN station file: one tightening station whose tool boltwatch reads over CAN.

All services of a station read the same file (``config/station.toml`` for the
embedded simulated station). Paths inside it (``station.joint``, ``can.dbc``,
``recorder.folder``) are relative to the file itself. The rig (the simulated
tool, also as an Open Protocol controller: ``serve rig --controller
openprotocol``), the acquisition, the predictor, ``simulate`` and ``predict``
need this kind: a joint, programs with motor speed and hard limits, a DBC.
A station whose tool a controller drives (``[openprotocol]`` without
``[can]``) has a file of its own kind (:mod:`shared.config.controller_station`);
:func:`load_station` refuses it, naming what the command needs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from shared.config.common_sections import (
    RecorderSection,
    SpoolSection,
    StationIdentity,
    ZenohSection,
    check_unique_ids,
    find_program,
    make_recordings_folder,
    recordings_folder,
    spool_folder,
)
from shared.config.controller_station import is_controller_station
from shared.config.final_stage import FinalStage
from shared.config.joint import JointConfig, load_joint
from shared.config.loading import StrictModel, read_toml, resolve_relative, validate
from shared.config.openprotocol import OpenProtocolSection, RigOpenProtocolSection
from shared.config.program_windows import ProgramWindows
from shared.config.quality import QualitySection
from shared.config.retention import RetentionSection
from shared.config.rig_parts import DEFAULT_PART_PATTERN, check_part_pattern, part_id
from shared.contract import MAX_SPINDLES, SensorRange, SpindleIds, StationDatabase
from shared.errors import CanDatabaseError, ConfigError


class StationSection(StationIdentity):
    """``[station]`` of a CAN station: its identity, the joint its tool tightens, its sensors."""

    joint: Path = Field(description="joint file, relative to this station file")
    has_force_sensor: bool = Field(
        default=True, description="false: no JointSensors on the bus, torque-only prediction"
    )
    spindles: int = Field(
        default=1,
        ge=1,
        le=MAX_SPINDLES,
        description="spindles tightening one part in one synchronised cycle (a multi-spindle "
        "system: each its own tool, curve and result, the cycle's common result OK only "
        "when every spindle is); 1: a single-spindle station",
    )

    @model_validator(mode="after")
    def _a_tool_for_each_spindle(self) -> StationSection:
        given = len(self.spindle_tool_ids)
        if given and given != self.spindles:
            raise ValueError(
                f"spindle_tool_ids names {given} tools for {self.spindles} spindles: one per "
                "spindle, or none (tool_id, tool_id + 1, ...)"
            )
        if not given and self.tool_id + self.spindles - 1 > 65535:
            raise ValueError(
                f"tool_id {self.tool_id} + {self.spindles - 1} spindles is beyond 65535 (the "
                "spindles' tools count up from tool_id): lower tool_id or give spindle_tool_ids"
            )
        if len(set(self.spindle_tool_ids)) < given:
            raise ValueError("spindle_tool_ids: each spindle is a tool of its own (an id twice)")
        return self


class CanSection(StrictModel):
    interface: Literal["udp_multicast", "socketcan", "virtual"]
    channel: str = Field(min_length=1, description="multicast group, can0, or a virtual bus name")
    port: int | None = Field(default=None, ge=1, le=65535, description="udp_multicast only")
    dbc: Path = Field(description="CAN database, relative to this station file")
    tool_commands: Literal["auto", "stop"] = Field(
        default="auto",
        description="'auto': command a program's final stage when the DBC has StageCommand "
        "and the tool controller says it takes it (ToolStage); 'stop': stop commands only",
    )
    spindle_id_stride: int = Field(
        default=2,
        ge=1,
        le=0x1000_0000,
        description="a multi-spindle station: spindle k's frames are at the DBC's ids plus "
        "(k - 1) times this (docs/reference/can-and-trace.md); every spindle's ids must "
        "differ from every other's and from CycleStart's",
    )

    @model_validator(mode="after")
    def _port_only_for_multicast(self) -> CanSection:
        if self.port is not None and self.interface != "udp_multicast":
            raise ValueError("port applies only to interface = 'udp_multicast'")
        return self


class Program(ProgramWindows):
    """A tightening program of the tool controller, selected by ``ProgramId`` on CAN,
    with the windows its runs are judged against (:mod:`shared.config.program_windows`)."""

    id: int = Field(ge=1, le=255)
    name: str
    target_force_n: float | None = Field(default=None, gt=0)
    target_torque_nm: float | None = Field(default=None, gt=0)
    motor_speed_rad_s: float = Field(gt=0, le=50, description="constant motor speed, φ̇_m")
    start_force_n: float = Field(
        default=0.0, ge=0, description="preload when the run starts (after snug, paper: 10 kN)"
    )
    max_torque_nm: float = Field(gt=0, description="hard limit: the tool stops by itself")
    max_force_n: float | None = Field(default=None, gt=0)
    max_angle_deg: float = Field(gt=0)
    max_time_s: float = Field(gt=0)
    joint: Path | None = Field(
        default=None,
        description="the joint this program tightens, relative to the station file "
        "(default: the station's station.joint)",
    )
    final_stage: FinalStage | None = Field(
        default=None,
        description="a final stage at a lower speed, and pulses back to the target "
        "(shared/config/final_stage.py); none: the tool runs at one speed and is stopped",
    )

    @model_validator(mode="after")
    def _has_a_target(self) -> Program:
        if self.target_force_n is None and self.target_torque_nm is None:
            raise ValueError("give target_force_n, target_torque_nm, or both")
        return self

    @model_validator(mode="after")
    def _limits_leave_room_for_the_target(self) -> Program:
        """A hard limit at or below its target would end every run on the limit."""
        for limit, target, unit in (
            ("max_force_n", "target_force_n", "N"),
            ("max_torque_nm", "target_torque_nm", "Nm"),
        ):
            limit_value, target_value = getattr(self, limit), getattr(self, target)
            if limit_value is not None and target_value is not None and limit_value <= target_value:
                raise ValueError(
                    f"{limit} {limit_value:g} {unit} is not above {target} {target_value:g} "
                    f"{unit}: every run would end on the tool's hard limit"
                )
        if self.target_force_n is not None and self.start_force_n >= self.target_force_n:
            raise ValueError(
                f"start_force_n {self.start_force_n:g} N is not below target_force_n "
                f"{self.target_force_n:g} N: the run would start past its target"
            )
        past = self.windows_past_limits()
        if past is not None:
            raise ValueError(past)
        return self

    @model_validator(mode="after")
    def _final_stage_fits(self) -> Program:
        """A final stage slower than the rundown, switching below the target."""
        stage = self.final_stage
        if stage is None:
            return self
        if stage.speed_rad_s >= self.motor_speed_rad_s:
            raise ValueError(
                f"final_stage.speed_rad_s {stage.speed_rad_s:g} rad/s is not below "
                f"motor_speed_rad_s {self.motor_speed_rad_s:g} rad/s: a final stage is slower"
            )
        switch_nm = stage.switch_torque_nm
        if switch_nm is not None:
            which, below = ("max_torque_nm", self.max_torque_nm)
            if self.target_torque_nm is not None:
                which, below = ("target_torque_nm", self.target_torque_nm)
            if switch_nm >= below:
                raise ValueError(
                    f"final_stage.switch_torque_nm {switch_nm:g} Nm is not below {which} "
                    f"{below:g} Nm: the tool would never run its final stage"
                )
        return self

    def limits_beyond(self, sensor_range: SensorRange) -> str | None:
        """What of this program's hard limits its sensors cannot report, or None."""
        for key, value, (low, high), unit in (
            ("max_torque_nm", self.max_torque_nm, sensor_range.torque_nm, "Nm"),
            ("max_force_n", self.max_force_n, sensor_range.force_n, "N"),
            ("max_angle_deg", self.max_angle_deg, sensor_range.angle_deg, "deg"),
        ):
            if value is not None and not low < value < high:
                return (
                    f"{key}: {value:g} {unit} is beyond what the sensor can report "
                    f"({low:g} to {high:g} {unit})"
                )
        return None


class PredictorSection(StrictModel):
    placement: Literal["edge", "line"] = Field(
        default="edge",
        description=(
            "edge: the acquisition decides on its own CAN thread (the stop path of one "
            "sample); line: a separate 'boltwatch serve predictor' decides over zenoh"
        ),
    )
    window_samples: int = Field(
        default=5, ge=3, le=200, description="n of eqs. 43-45 (why 5: predictor core settings)"
    )
    max_process_intensity: float | None = Field(
        default=None, gt=0, description="I_max of eq. 70; none: no intensity stop"
    )
    constant_band: float | None = Field(
        default=None, gt=0, description="S_i of eq. 71 as a fraction of the running mean"
    )
    constant_window: int = Field(default=5, ge=2, le=100, description="n_K of eq. 71")


class RigSection(StrictModel):
    """Knobs of the simulated tool and sensors (ignored by a real station)."""

    inertia_kg_m2: float = Field(default=2.0e-4, gt=0, description="screw + socket")
    damping_ratio: float = Field(default=0.15, ge=0, lt=1)
    mu_stick_scatter: float = Field(default=0.01, ge=0, lt=0.5, description="relative σ per event")
    torque_noise_nm: float = Field(default=0.2, ge=0)
    force_noise_n: float = Field(default=30.0, ge=0)
    angle_noise_deg: float = Field(default=0.01, ge=0)
    settle_time_s: float = Field(default=0.03, gt=0, description="samples sent after the stop")
    stage_commands: bool = Field(
        default=True,
        description="the simulated controller takes StageCommand (a program's final stage, "
        "pulses) and says so in ToolStage; false: it only stops, as an older controller",
    )
    pause_between_runs_s: float = Field(default=0.5, ge=0)
    seed: int | None = Field(default=None, description="none: a fresh seed per process")
    bolts_per_part: int = Field(
        default=4,
        ge=0,
        le=10_000,
        description="runs per part: the rig puts each part's id on boltwatch/<st>/part "
        "before its first run, as the line's PLC would; 0: no part ids",
    )
    part_pattern: str = Field(
        default=DEFAULT_PART_PATTERN,
        description="the id of each part: {station} and {first_run_id} (its first bolt's run)",
    )
    openprotocol: RigOpenProtocolSection = Field(
        default_factory=RigOpenProtocolSection,
        description="the simulated controller toward an Open Protocol bridge",
    )

    @field_validator("part_pattern")
    @classmethod
    def _part_pattern_fits(cls, pattern: str) -> str:
        return check_part_pattern(pattern)

    def part_id(self, station: str, first_run_id: int) -> str:
        """The id of the part whose first bolt is run ``first_run_id``."""
        return part_id(self.part_pattern, station, first_run_id)


class StationConfig(StrictModel):
    station: StationSection
    can: CanSection
    zenoh: ZenohSection
    programs: list[Program] = Field(min_length=1)
    predictor: PredictorSection = PredictorSection()
    rig: RigSection = RigSection()
    recorder: RecorderSection
    spool: SpoolSection = SpoolSection()
    quality: QualitySection = QualitySection()
    retention: RetentionSection = RetentionSection()
    openprotocol: OpenProtocolSection | None = Field(
        default=None, description="the station's tool controller speaks Open Protocol"
    )

    @model_validator(mode="after")
    def _program_ids_unique(self) -> StationConfig:
        check_unique_ids(self.programs, "program")
        return self

    def program(self, program_id: int) -> Program:
        """The program with ``program_id``; KeyError names the known ids."""
        return find_program(self.programs, program_id, self.station.id, "program")


class LoadedStation:
    """A validated station file with its paths resolved and its joint loaded."""

    def __init__(
        self,
        path: Path,
        config: StationConfig,
        joint: JointConfig,
        sensor_range: SensorRange,
        program_joints: dict[int, JointConfig] | None = None,
    ) -> None:
        self.path = path
        self.config = config
        self.joint = joint
        #: the joints of the programs that name their own (``programs[].joint``), by id
        self.program_joints = program_joints or {}
        #: what the station's sensors can measure: the ranges of its DBC's signals
        self.sensor_range = sensor_range

    @property
    def station_id(self) -> str:
        return self.config.station.id

    @property
    def dbc_path(self) -> Path:
        return resolve_relative(self.config.can.dbc, self.path)

    @property
    def joint_path(self) -> Path:
        return resolve_relative(self.config.station.joint, self.path)

    def joint_of(self, program_id: int) -> JointConfig:
        """The joint program ``program_id`` tightens: its own, else the station's."""
        return self.program_joints.get(program_id, self.joint)

    @property
    def spool_folder(self) -> Path:
        return spool_folder(self.path, self.config.spool, self.recordings_folder)

    @property
    def recordings_folder(self) -> Path:
        return recordings_folder(self.path, self.config.recorder)

    def make_recordings_folder(self) -> Path:
        """The recordings folder, made if missing; ConfigError (file, key, why) if it cannot be."""
        return make_recordings_folder(self.path, self.config.recorder)


def load_station(path: Path) -> LoadedStation:
    """Load a CAN station file and the joint file it names; every error names file and key.

    A controller station's file (``[openprotocol]`` without ``[can]``) is a
    ConfigError saying what the command needs: the services of a CAN station
    (rig, acquisition, predictor) and ``simulate`` / ``predict`` need a joint,
    a DBC and programs with motor and limits. Whatever the kind:
    :func:`shared.config.station_kinds.load_any_station`.
    """
    path = Path(path)
    data = read_toml(path)
    if is_controller_station(data):
        raise ConfigError(
            f"{path}: can: a controller station ([openprotocol] without [can]) has no CAN bus, "
            "joint or motor; this needs a CAN station's file ([can], station.joint, programs "
            "with motor speed and hard limits, e.g. config/station.toml). A controller "
            f"station runs its bridge: boltwatch serve openprotocol --config {path}"
        )
    return can_station(path, data)


def can_station(path: Path, data: dict[str, Any]) -> LoadedStation:
    """The CAN station of ``path`` from its TOML ``data``: validated, its joints and DBC read."""
    config = validate(StationConfig, data, path)
    joint_path = resolve_relative(config.station.joint, path)
    if not joint_path.is_file():
        raise ConfigError(f"{path}: station.joint: file not found: {joint_path}")
    dbc_path = resolve_relative(config.can.dbc, path)
    if not dbc_path.is_file():
        raise ConfigError(f"{path}: can.dbc: file not found: {dbc_path}")
    try:
        database = StationDatabase(dbc_path)
        sensor_range = SensorRange.of_database(database)
    except CanDatabaseError as err:
        raise ConfigError(f"{path}: can.dbc: {err}") from err
    try:
        SpindleIds(database, config.station.spindles, config.can.spindle_id_stride)
    except CanDatabaseError as err:
        raise ConfigError(f"{path}: can.spindle_id_stride: {err}") from err
    for index, program in enumerate(config.programs):
        beyond = program.limits_beyond(sensor_range)
        if beyond is not None:
            raise ConfigError(
                f"{path}: programs[{index}].{beyond} in the scaling of {dbc_path}: the tool could "
                "never send a reading at its own limit (widen the signal in the DBC or lower "
                "the limit)"
            )
        if program.has_force_window and not config.station.has_force_sensor:
            raise ConfigError(
                f"{path}: programs[{index}]: force_min_n / force_max_n need a force sensor "
                "(station.has_force_sensor is false: no preload to judge)"
            )
        beyond = program.windows_beyond(sensor_range)
        if beyond is not None:
            raise ConfigError(
                f"{path}: programs[{index}].{beyond} in the scaling of {dbc_path}: no reading "
                "could ever be judged against it (narrow the window or widen the signal)"
            )
    bridge, rig_controller = config.openprotocol, config.rig.openprotocol
    if bridge is not None and bridge.keep_alive_s >= rig_controller.link_timeout_s:
        raise ConfigError(
            f"{path}: openprotocol.keep_alive_s: {bridge.keep_alive_s:g} s is not below "
            f"rig.openprotocol.link_timeout_s {rig_controller.link_timeout_s:g} s: the "
            "simulated controller would drop the link between two keep-alives"
        )
    program_joints = {}
    for index, program in enumerate(config.programs):
        if program.joint is not None:
            program_joint = resolve_relative(program.joint, path)
            if not program_joint.is_file():
                raise ConfigError(
                    f"{path}: programs[{index}].joint: file not found: {program_joint}"
                )
            program_joints[program.id] = load_joint(program_joint)
    return LoadedStation(path, config, load_joint(joint_path), sensor_range, program_joints)
