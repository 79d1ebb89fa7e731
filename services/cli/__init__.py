"""The ``boltwatch`` command line: the one place that knows every service.

- :mod:`.main` (entry point; ``__main__`` for ``python -m services.cli``),
  :mod:`.commands` (one module per subcommand), :mod:`.command_options` (options
  several commands share), :mod:`.error_lines` (an OSError as one line naming the
  path)
- ``boltwatch up``: :mod:`.station_run`, :mod:`.station_supervisor`, :mod:`.run_table`,
  :mod:`.run_tally` (which summaries count: runs seen starting, once)
- ``boltwatch status``: :mod:`.station_status_text` (what it prints of
  :mod:`shared.line_status`, which collects it; the line's page shares that);
  with ``wear --plant``: :mod:`.router_client` (a client of the line's router)
- ``boltwatch import``: :mod:`.import_destination` (recordings or trace CSVs); the
  import itself, with the predictor's replay of each run, is
  :mod:`shared.offline.controller_import`
- ``boltwatch predict``: :mod:`.predict_settings` (its options, or a station's program)
- ``boltwatch inspect --overlay``: :mod:`.run_overlay` (run ids or paths to runs, drawn)
- :mod:`.reference_pages` (``docs/reference/cli.md`` and ``channels.md``, written from
  the parser and the channel table)
"""
