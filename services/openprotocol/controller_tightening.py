"""One tightening as a controller reports it: its result and its torque and angle curves.

The controller's result comes as MID 0061 (pushed live) or 0065 (fetched by
id after a reconnect); each revision carries a different set of fields. The
bridge reads what it needs of either into :class:`ResultFigures` (in
:mod:`.result_reading`), so the rest of the bridge works on one shape. The
curves come as MID 0900, one per trace type (torque, angle), paired with the
result by the result data identifier, which is the tightening id; they may
arrive before or after the result, or never.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class ResultFigures:
    """What the bridge uses of a controller's result (0061 or 0065), in SI-ish units.

    A limit or target the controller leaves at 0 on both sides of a window is
    no window (None); a field its revision does not carry is None.
    """

    tightening_id: int
    program_id: int  # the parameter set (pset) it tightened with
    time_ns: int  # the controller's time stamp of the result, in its time zone
    ok: bool  # the tightening status: 1 OK, 0 NOK
    torque_nm: float
    torque_min_nm: float | None
    torque_max_nm: float | None
    torque_target_nm: float | None
    angle_deg: float
    angle_min_deg: float | None
    angle_max_deg: float | None
    angle_target_deg: float | None
    part_id: str  # the VIN / identifier of the part ("" none)
    batch_size: int | None
    batch_counter: int | None
    strategy: str  # "" when the revision carries none
    revision: int  # of the message it came in
    filled: bool  # fetched with 0064 (not pushed live)
    #: what tells this result from another of the same id: the controller's time stamp,
    #: pset, torque, angle, verdict and part, as it wrote them (0061 and 0065 alike)
    key: str = ""
    #: the controller's time stamp was one no clock holds (before 2000, or ahead of the
    #: bridge's): ``time_ns`` is when the bridge received it instead
    clock_refused: bool = False
    #: a multi-spindle system's tightening (a sync tightening id other than 0, 0061 and 0065
    #: revision 2): the cycle's sync id, and the spindle: its channel id (a 0061's; a 0065
    #: carries none: None)
    sync_id: int | None = None
    spindle: int | None = None


@dataclass(frozen=True, slots=True)
class Curve:
    """One 0900 trace: samples at the controller's own timing.

    ``values`` are read as the 0900 declares them (big-endian, its scaling);
    ``sample_bytes`` and ``coefficient`` keep what came, so that the samples
    can be read another way (:mod:`.curve_check`)."""

    tightening_id: int
    kind: str  # "torque" or "angle"
    start_ns: int  # the controller's time stamp of the trace's first sample
    time_step_s: float
    values: tuple[float, ...]  # in the trace's unit: Nm, deg
    sample_bytes: bytes = b""  # the samples as they came, 2 bytes each
    coefficient: float = 1.0  # value = raw sample * coefficient, as the 0900 declares it

    def time_ns(self, index: int) -> int:
        return self.start_ns + round(index * self.time_step_s * 1e9)


@dataclass(frozen=True, slots=True)
class Tightening:
    """A result and the curves that came for it (either may be None: never came)."""

    result: ResultFigures
    torque: Curve | None
    angle: Curve | None

    @property
    def complete(self) -> bool:
        return self.torque is not None and self.angle is not None
