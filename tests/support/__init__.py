"""Every helper the tests share (no test module imports another): real processes and sockets.

Peers written independently of the code they test:
:mod:`.openprotocol_controller` (a controller from the specification's text,
with :mod:`.openprotocol_core`, :mod:`.openprotocol_link`,
:mod:`.openprotocol_wire`, :mod:`.openprotocol_messages`,
:mod:`.openprotocol_results`, :mod:`.openprotocol_traces`),
:mod:`.foxglove_client` (the Foxglove WebSocket protocol),
:mod:`.openprotocol_proxy` (a TCP proxy that damages what passes).

- messages and data: :mod:`.factories` (run summaries, samples, events, results and
  programs with plausible values, changed by keyword),
  :mod:`.synthetic_runs` (synthetic traces), :mod:`.recorded_runs` (a whole run
  as a station publishes it), :mod:`.openprotocol_golden`,
  :mod:`.openprotocol_examples` (Open Protocol messages with their bytes),
  :mod:`.imported_runs` (real controller runs imported), :mod:`.model_band_runs`
  (the core over a simulated joint)
- stations and files: :mod:`.paths` (the repository's files), :mod:`.config_files`
  (station files written from the shipped one), :mod:`.station_files` (isolated
  station files for system tests), :mod:`.free_ports` (their routers' and CAN
  buses' ports, never the kernel's to hand out), :mod:`.rig_fixtures` (rigs and
  programs)
- on zenoh: :mod:`.listener` (a station's messages as a test hears them, decoded
  by channel)
- services in a test: :mod:`.live_recorder`, :mod:`.recorder_driver`,
  :mod:`.live_predictor`, :mod:`.bridge_harness`, :mod:`.tcp_controller` (a small
  controller built on the codec), :mod:`.simulated_controller` (the rig's
  controller in a test)
- processes: :mod:`.station_up` (``boltwatch up``), :mod:`.router_process` (a
  router, ``boltwatch`` as a command), :mod:`.live_station` (a whole station),
  :mod:`.plant`, :mod:`.netns_line` (lines in network namespaces),
  :mod:`.can_injector` (frames on the CAN bus), :mod:`.disk_faults` (a full or
  read-only disk)
- databases: :mod:`.postgres_server` (a throwaway PostgreSQL server; the fixtures
  ``postgres_server`` and ``postgres_url`` in ``tests/conftest.py``),
  :mod:`.old_results_store` (a results store as an older boltwatch left it)
- deployment: :mod:`.compose_layout`, :mod:`.compose_line` (the compose TLS line's
  services run on loopback), :mod:`.access_rules`
- OPC UA: :mod:`.opcua_client` (node-opcua's client as a process: ``opcua_client.js``,
  with ``opcua_browse_tree.js``, a browser's tree of the address space),
  :mod:`.opcua_certificates`, :mod:`.opcua_line` (``serve opcua`` signed and encrypted
  beside a line, the client subscribed), :mod:`.address_space_picture` (that tree,
  photographed)
- pictures: :mod:`.chromium` (Debian's chromium for playwright)
- :mod:`.fuzz` (hostile payloads for the live services), :mod:`.bad_arguments`
  (every bad argument of every command)
- :mod:`.import_rules` (``make lint``: no test module imports another)
"""
