"""The simulated rig: tool controller and sensors of one station on a CAN bus.

Physics from the paper's Sections 3-4 (:mod:`services.rig.physics`, pure);
the runtime of a real station never imports this package.

- :mod:`.physics` (one tightening, hybrid stick-slip; pure), :mod:`.slip_oscillator`
  (the sliding screw in closed form)
- :mod:`.controller` (the tool controller of one run on the physics; pure)
- :mod:`.realtime` (the controller paced at 1 kHz on a CAN bus), :mod:`.frames`
  (its frames through the station's DBC)
- :mod:`.part_scanner` (the line's PLC, simulated: each part's id on zenoh
  before its first run)
- :mod:`.service` (``boltwatch serve rig``), :mod:`.arguments`, :mod:`.selection`
  (which program and seed; shared with ``boltwatch simulate``)
"""
