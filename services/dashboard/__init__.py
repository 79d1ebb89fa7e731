"""``boltwatch serve dashboard``: the supervisor's page of the line, live in a browser.

A service of its own: it meets the others on zenoh only (import-linter's
independence contract) and collects what ``boltwatch status`` collects
(:mod:`shared.line_status`).

- :mod:`.arguments` (its options, light), :mod:`.service` (``main``: files,
  session, server)
- :mod:`.connection_guard` (the server's bounds: open files, connections,
  idle time, request size, and one log line per kind of client fault)
- :mod:`.line_board` (what the page shows, pure: status's collectors, the last
  results and a multi-spindle station's cycles, stop reasons, alerts and wear per
  station), :mod:`.tools_due` (the line's tools due soonest: each one's forecast and
  chart, pure)
- :mod:`.line_link` (the zenoh session, opened in the background: the page
  is served before the router answers)
- :mod:`.board_feed` (zenoh: subscriptions, liveliness and wear queries per
  window, its health token)
- :mod:`.web_app` (aiohttp: the page, ``/board.json``, server-sent ``/events``,
  the part search ``/api/results``, the NOK list ``/api/noks``)
- :mod:`.part_search` (a part's tightenings, and the line's NOKs, in the results
  stores of the station files, in worker threads: :mod:`shared.results`)
- :mod:`.json_replies` (the JSON replies' headers, an error in words, a reply kept
  gzipped)
- a run's curve: :mod:`.run_routes` (``/api/runs/ST/RUN``: its view, its part's
  runs, its program's band, a multi-spindle run's cycle, its files),
  :mod:`.run_locator` (where its recording is: the results store names it, inside the
  station's recordings folder),
  :mod:`.run_views` (read off the event loop, bounded, shared),
  :mod:`.run_cache` (runs read, kept until their files change),
  :mod:`.cycle_runs` (a multi-spindle cycle's runs overlaid, from its one file),
  :mod:`.viewer_links` (Rerun's and Foxglove's links, their origins)
- ``page/``: ``index.html``, ``dashboard.css``, ``dashboard.js`` (the
  stations; a multi-spindle station's rows grouped by cycle), ``part_search.js`` (the
  search box, the NOK list),
  ``run_view.js`` (a run's panel), ``run_specs.js`` (what its charts draw),
  ``run_chart.js`` (the page's own canvas chart), ``tools_due.js`` and
  ``tools_due.css`` (the tools due soonest) (served by the app; nothing from the
  internet)
"""
