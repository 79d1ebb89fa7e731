"""Fuzzing the live services: hostile payloads fed to the real services over real zenoh.

- :mod:`.payloads`  hypothesis strategies: random bytes, random JSON (deep
  nesting, huge documents), messages with a field out of its bounds, and
  messages with extreme values within them
- :mod:`.targets`   each service built in-process on a real zenoh session on
  loopback, with what it counted and a proof that it still serves
- :mod:`.rules`     what each service refuses beyond the contract's bounds
- :mod:`.property`  the property every target must keep under a stream of
  payloads, shared by the tests (``tests/unit/*/test_*_fuzz.py``, bounded)
  and the long run (``tests/benchmarks/fuzz_services.py --minutes N``)
"""
