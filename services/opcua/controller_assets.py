"""A station's controller in its joining system's ``AssetManagement/Assets/Controllers``.

The model asks each joining system for at least one controller (the
``<Controller>`` placeholder is mandatory). Each station's is one object
``Controller`` (node id ``s=<station>/controllers/1``) with IJT's
``IControllerType`` interface, its figures :mod:`.controller_values`':

```
Controller                      BaseObjectType, HasInterface IControllerType
├── Identification              MachineryComponentIdentificationType: SerialNumber,
│                               SoftwareRevision, Manufacturer, Model
└── Parameters/Type             MultiStateDiscreteType, 4 (JOINING_PROCESS_CONTROLLER),
                                the model's EnumStrings
```

The service writes it at start and whenever the wear ledger is read again (a
controller tells its serial with a tool's data).
"""

from __future__ import annotations

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.asset_nodes import AssetNodes, Figures, asset_namespaces
from services.opcua.controller_values import JOINING_PROCESS_CONTROLLER, ControllerIdentity

#: numeric ids in IJT Base
CONTROLLER_INTERFACE = 1003  # IControllerType
CONTROLLER_TYPE_DECLARATION = 6128  # IControllerType/Parameters/Type (its EnumStrings)
CONTROLLER_NAME = "Controller"

V = ua.VariantType


def _localized(text: str | None) -> ua.LocalizedText | None:
    return None if text is None else ua.LocalizedText(text)


def _figures(identity: ControllerIdentity) -> Figures:
    return {
        "Identification/SerialNumber": (identity.serial_number, V.String),
        "Identification/SoftwareRevision": (identity.software_revision, V.String),
        "Identification/Manufacturer": (_localized(identity.manufacturer), V.LocalizedText),
        "Identification/Model": (_localized(identity.model), V.LocalizedText),
        "Parameters/Type": (identity.kind, V.Byte),
    }


class ControllerAsset:
    """The controller of one joining system."""

    def __init__(self, server: Server, nodes: AssetNodes) -> None:
        self._server = server
        self._nodes = nodes

    @classmethod
    async def create(cls, server: Server, station: str, system: Node) -> ControllerAsset:
        names = await asset_namespaces(server)
        ijt = names["ijt"]
        folder = await system.get_child(
            [f"{ijt}:AssetManagement", f"{ijt}:Assets", f"{ijt}:Controllers"]
        )
        nodes = await AssetNodes.add(
            folder, f"{station}/controllers/1", CONTROLLER_NAME, CONTROLLER_INTERFACE, names
        )
        await nodes.identification(("SerialNumber", "SoftwareRevision", "Manufacturer", "Model"))
        await nodes.kind(CONTROLLER_TYPE_DECLARATION, JOINING_PROCESS_CONTROLLER)
        return cls(server, nodes)

    async def update(self, identity: ControllerIdentity) -> None:
        await self._nodes.write(self._server, _figures(identity))
