"""Test doubles that speak real protocols, written independently of the code they test.

- `openprotocol_wire`: framing (header, NUL, binary part) and field formatting; a stream
  reader that takes any split of the stream.
- `openprotocol_messages`: MID 0002, 0004, 0005, 0041, 0071, 0074, 0076 data fields.
- `openprotocol_results`: tightening results and their MID 0061 / MID 0065 data fields.
- `openprotocol_traces`: torque and angle curves of a tightening and their MID 0900.
"""
