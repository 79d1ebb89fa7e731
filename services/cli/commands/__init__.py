"""One module per ``boltwatch`` subcommand.

Each module defines ``NAME`` (the subcommand), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (the exit status).
:mod:`services.cli.main` finds them with ``pkgutil``; heavy imports happen
inside ``run`` so that ``boltwatch --help`` stays fast.
"""
