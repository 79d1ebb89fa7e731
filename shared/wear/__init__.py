"""The wear ledger: accumulated vibration intensity per tool (eq. 69).

- :mod:`.wear_ledger`: the SQLite ledger
- :mod:`.wear_tool_data`: what controllers said of their tools (serial, calibration, service)
- :mod:`.wear_bound`: what a run can have taken, the bound a summary must keep
- :mod:`.wear_ledger_file`: a ledger made whole; a broken one recognised and moved aside
- :mod:`.wear_since_service`: a tool's intensity since service, kept from the runs added
- :mod:`.wear_watch`: summaries in, alerts out, a failing or broken ledger waited out
- :mod:`.wear_waiting`: runs still waiting when the recorder stops
- :mod:`.wear_reset`: ``boltwatch wear reset``
- :mod:`.wear_table`: the ledger as a table (``boltwatch wear``)
- :mod:`.wear_plant`: every line's ledger merged (``boltwatch wear --plant``)
"""
