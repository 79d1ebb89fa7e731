"""One module per ``boltwatch`` subcommand.

Each module defines ``NAME`` (the subcommand), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (the exit status).
:mod:`services.cli.main` finds them with ``pkgutil``; heavy imports happen
inside ``run`` so that ``boltwatch --help`` stays fast.

    up           the simulated station (or a line) end to end, a table of its runs
    serve        one long-running service: rig, acquisition, predictor, recorder, router
    status       which stations and services are alive, bus faults, the last run
    health       exit 0 if a service is alive (container health checks)
    simulate     one tightening offline, its trace CSV
    predict      the predictor over a trace CSV: events and stops as JSON Lines
    model        the paper's analytical model of a joint: report, plot, rig validation
    inspect      a recorded run as a post-mortem PNG of the paper's figures
    export       a recorded run's samples as a trace CSV
    recover      a truncated recording (.mcap or .rrd) made valid
    import_runs  ``boltwatch import``: controller JSON runs as recordings or trace CSVs
    wear         the wear ledger per tool, a tool's service, a broken ledger replaced
    report       statistics per program over recorded results (X̄/R, Cp/Cpk, NOK Pareto)
    results      tightenings found in the results store; the store rebuilt from recordings
    recordings   the recordings' upkeep: ``prune`` applies the station file's ``[retention]``
    opcua_user   ``boltwatch opcua-user``: the users file of ``serve opcua --users``
"""
