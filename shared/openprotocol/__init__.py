"""Atlas Copco Open Protocol, the pure protocol layer: bytes in, messages out.

No sockets here: the simulated controller (``services/rig``) and the bridge
(``boltwatch serve openprotocol``) both use it, each side encoding and
decoding.

- :mod:`.framing`: :class:`~.framing.Frame` (the 20-byte header and data),
  :func:`~.framing.frame_bytes`, :class:`~.framing.FrameReader` (frames out of a
  TCP stream: partial reads, garbage, bad lengths)
- :mod:`.codec`: :func:`~.codec.decode` / :func:`~.codec.encode` by MID and
  revision, :data:`~.codec.SUPPORTED_REVISIONS`, :class:`~.codec.UnknownMessage`
- :mod:`.dialect`: what controllers differ on when writing (header fill, NUL
  terminator, 0900 byte order and separator) and the defaults
- :mod:`.errors`: :class:`~.errors.OpenProtocolError`, the one exception
- messages: :mod:`.session` (0001-0005, 9999), :mod:`.results` (0060-0065,
  layouts in :mod:`.result_layouts`), :mod:`.subscriptions` (0008/0009, 0900
  subscription data), :mod:`.traces` (0900), :mod:`.tool_data` (0040/0041),
  :mod:`.alarms` (0070-0077)
- :mod:`.fields` (fixed-width field layouts, read and written),
  :mod:`.timestamps` (controller time text <-> ns since the epoch)
"""
