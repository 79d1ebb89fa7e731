"""Acquisition: CAN frames in, 1 kHz samples out on zenoh; stop decisions back to CAN.

- :mod:`.service` (``boltwatch serve acquisition``: the bus, zenoh, the decision
  subscriber), :mod:`.arguments`
- :mod:`.acquisition` (the loop: frames in, samples and run states out, decisions
  to StopCommands, every fault counted), :mod:`.frame_decoder` (one frame against
  the DBC), :mod:`.pairing` (the two sensor frames of a sample, by Counter),
  :mod:`.spindle_lane` (one spindle's run, pairing and commands: a multi-spindle
  station has one per spindle), :mod:`.tool_commands` (what the station sends its tool)
- :mod:`.zenoh_outlet` (samples, run states and bus counters onto zenoh)
- :mod:`.decider` (what may decide on the CAN thread, for the station's predictor
  placed at the edge; the acquisition never imports the predictor, ``serve`` hands
  it in)
"""
