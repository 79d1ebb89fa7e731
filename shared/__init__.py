"""The library every boltwatch process uses, one room per concept, layered top to bottom.

Each room's ``__init__`` says what each of its files is and re-exports what
callers use: import from the room (``from shared.quality import judge``), so a
move inside it breaks nobody. ``shared`` never imports ``services``;
import-linter holds the layers in ``make lint`` (``pyproject.toml``):

- :mod:`.offline`: after-the-fact work over recordings (post-mortem, overlay,
  report, controller import); :mod:`.retention`: how long the recordings are
  kept (the station file's ``[retention]``, never a file whose results are not stored)
- :mod:`.stickslip`: the paper's predictor as a library (pure); :mod:`.results`: the
  results store (every tightening's result, SQLite or PostgreSQL)
- :mod:`.recordings` (where a run's files go, MCAP, Rerun), :mod:`.wear` (the
  ledger), :mod:`.quality` (OK/NOK, Cpk; pure), :mod:`.model` (the paper's
  analytical model; pure), :mod:`.runtime` (a service's life, zenoh, CAN, logging)
- :mod:`.config` (station, joint and line files), :mod:`.line_status` (what a
  line's stations say, aggregated; pure)
- :mod:`.contract` (what crosses a process or file boundary: messages, channels,
  keys, codec, bounds, the DBC, the trace CSV), :mod:`.openprotocol` (Open
  Protocol bytes <-> messages, no sockets), :mod:`.files` (folders; an OSError in
  one line), :mod:`.option_types` (command-line values that refuse impossible numbers)
- :mod:`.errors`: the exception tree
"""
