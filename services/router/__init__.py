"""The line's zenoh router: the rendezvous that station services connect to."""
