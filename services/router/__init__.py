"""The line's zenoh router: the rendezvous that station services connect to.

- :mod:`.service` (``boltwatch serve router``), :mod:`.arguments`
- :mod:`.access_control` (with TLS: who may put what, by certificate common name)
"""
