"""Test doubles that speak real protocols, written independently of the code they test.

- `openprotocol_controller`: `SpecController`, an Open Protocol tightening controller on
  127.0.0.1 written from the public specification (what it answers to each MID).
- `openprotocol_core`: its settings, records, serving thread, timers and cut writes.
- `openprotocol_link`: one integrator's link state, the write cutting of each write mode,
  and the MID 0900 subscription's extra data.
- `openprotocol_wire`: framing (header, NUL, binary part) and field formatting; a stream
  reader that takes any split of the stream.
- `openprotocol_messages`: MID 0002, 0004, 0005, 0041, 0071, 0074, 0076 data fields.
- `openprotocol_results`: tightening results and their MID 0061 / MID 0065 data fields.
- `openprotocol_traces`: torque and angle curves of a tightening and their MID 0900.
"""
