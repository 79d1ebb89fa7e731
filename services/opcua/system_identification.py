"""A station as the identification of its IJT joining system, pure (no asyncua).

:func:`system_identification` gives what :meth:`.joining_systems.JoiningSystem.identify`
writes into the joining system's ``Identification``
(``JoiningSystemIdentificationType``, OPC 40450-1, 7.2), from the station
file's ``[station]`` (the plant model) and what reads the tool:

| property | value |
|---|---|
| ``Name`` | ``[station] name``, else its id |
| ``SystemId`` | the station's id (the ``ResultId``'s first part) |
| ``Location`` | ``plant <plant>, line <line>`` of those named; none when neither is |
| ``JoiningTechnology`` | ``Tightening`` |
| ``Description`` | what reads the tool: CAN, or the Open Protocol controller's address |

The rest (``Manufacturer``, ``Model``, ``SerialNumber``, ``IntegratorName``,
``ProductInstanceUri``...) is not known to boltwatch and has no value.
"""

from __future__ import annotations

from dataclasses import dataclass

from services.opcua.result_values import JOINING_TECHNOLOGY
from shared.config import AnyStation, ControllerStation


@dataclass(frozen=True, slots=True)
class SystemIdentification:
    name: str
    system_id: str
    location: str | None
    description: str
    joining_technology: str = JOINING_TECHNOLOGY


def system_identification(station: AnyStation) -> SystemIdentification:
    identity = station.config.station
    where = [
        f"{kind} {value}"
        for kind, value in (("plant", identity.plant), ("line", identity.line))
        if value
    ]
    if isinstance(station, ControllerStation):
        link = station.config.openprotocol
        description = (
            f"tightening station {identity.id}: an Open Protocol controller at "
            f"{link.host}:{link.port}, read by boltwatch"
        )
    else:
        description = (
            f"tightening station {identity.id}: torque, angle and preload over CAN, "
            "stopped by boltwatch"
        )
    return SystemIdentification(
        name=identity.name or identity.id,
        system_id=identity.id,
        location=", ".join(where) or None,
        description=description,
    )
