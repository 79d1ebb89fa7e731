"""The Open Protocol bridge: a tightening controller's results and curves on the station's channels.

``boltwatch serve openprotocol --config STATION`` connects to the controller
named in the station file's ``[openprotocol]`` section as an Open Protocol
integrator (TCP, port 4545) and publishes what a CAN station's acquisition and
predictor would (``docs/how-to/openprotocol-controller.md``).

- :mod:`.service` (the service: zenoh, the queued publisher, the health token,
  the counters once a second), :mod:`.arguments`
- :mod:`.bridge` (the link's life: connect, session, fill the gap, publish,
  reconnect with back-off)
- :mod:`.controller_link` (the TCP connection: bytes in and out, frames, a dead link)
- :mod:`.controller_session` (the integrator's session: start, subscribe with
  revision fall-back, requests and their answers, keep-alive, refused frames)
- :mod:`.controller_tightening` (a result and its curves, in the bridge's terms),
  :mod:`.result_reading` (0061/0065 and 0900 into them)
- :mod:`.pending_tightenings` (results and curves paired, in id order, once;
  what to fetch after a gap), :mod:`.published_ids` (the watermark kept across
  restarts; a controller's new epoch)
- :mod:`.tightening_messages` (a tightening as a CAN station's messages of a run)
- :mod:`.controller_reports` (tool data 0041 and alarms 0071-0076)
- :mod:`.bridge_counts` (the counters of BridgeStats, faults logged once per kind)
"""
