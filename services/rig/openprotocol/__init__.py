"""The simulated rig as an Open Protocol controller (``serve rig --controller openprotocol``).

The same physics and run controller as the CAN rig, with the controller's own
conventional shutoff (a tool on Open Protocol stops itself; boltwatch only
watches), behind a TCP server that speaks Atlas Copco's Open Protocol through
the codec of :mod:`shared.openprotocol`, as real controllers do.

- :mod:`.tightening` (one run of the physics and the controller's result of it; pure),
  :mod:`.result_messages` (that result as MIDs 0061, 0065, 0900; pure)
- :mod:`.simulated_tool` (the tool on its own pace, listened to or not)
- :mod:`.result_store` (the results kept to serve by id, bounded),
  :mod:`.tightening_counter` (the last tightening id, kept across restarts)
- :mod:`.controller_state` (results, alarm, tool data, revisions, how it writes),
  :mod:`.controller_counters` (what it counts and logs)
- :mod:`.integrator_link` (one integrator's session: frames in, bytes out; no sockets)
- :mod:`.controller_server` (the TCP side: listen, accept, read, write, timers)
- :mod:`.simulated_controller` (tool and server joined), :mod:`.controller_service`
  (its ``main``)
"""
