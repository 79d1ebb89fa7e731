"""Fuzzing the live services: hostile payloads fed to the real services over real zenoh.

- :mod:`.payloads`  hypothesis strategies: random bytes, random JSON (deep
  nesting, huge documents), messages with a field out of its bounds, and
  messages with extreme values within them
"""
