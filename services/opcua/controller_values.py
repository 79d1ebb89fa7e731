"""A station's controller as the values of an IJT controller asset, pure (no asyncua).

:func:`controller_identity` gives what :mod:`.controller_assets` writes into
the joining system's ``AssetManagement/Assets/Controllers/Controller`` (an
object with IJT's ``IControllerType`` interface, OPC 40450-1, 8.3.4):

- a controller station's: the newest of what its controller said of itself
  in a tool's data (Open Protocol MID 0041: the controller's serial number and
  software version, kept in the wear ledger); nothing before it has said it;
- a CAN station's: boltwatch's acquisition, which reads the tool and stops it
  (manufacturer ``boltwatch``, the installed version, no serial number).

Both are joining process controllers (``Parameters/Type`` 4 of IJT's
EnumStrings: JOINING_PROCESS_CONTROLLER).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from shared.wear import ToolWear

#: IControllerType's Parameters/Type: JOINING_PROCESS_CONTROLLER
JOINING_PROCESS_CONTROLLER = 4
#: a CAN station's controller
BOLTWATCH = "boltwatch"
CAN_MODEL = "boltwatch acquisition (CAN)"


@dataclass(frozen=True, slots=True)
class ControllerIdentity:
    #: Identification/SerialNumber and SoftwareRevision ("": not known)
    serial_number: str
    software_revision: str
    #: Identification/Manufacturer and Model (None: not known)
    manufacturer: str | None
    model: str | None
    #: Parameters/Type
    kind: int = JOINING_PROCESS_CONTROLLER


def controller_identity(
    is_controller_station: bool, tools: Sequence[ToolWear], boltwatch_version: str
) -> ControllerIdentity:
    """The controller of a station whose ledger knows ``tools`` (its own)."""
    if not is_controller_station:
        return ControllerIdentity("", boltwatch_version, BOLTWATCH, CAN_MODEL)
    said = [tool.controller for tool in tools if tool.controller is not None]
    if not said:
        return ControllerIdentity("", "", None, None)
    newest = max(said, key=lambda controller: controller.received_ns)
    return ControllerIdentity(
        newest.controller_serial or "", newest.controller_software or "", None, None
    )
