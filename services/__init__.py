"""The boltwatch services: rig (simulated tool + sensors), acquisition,
predictor, recorder, the line's zenoh router, the Open Protocol bridge, the
line's web page (dashboard), and the ``boltwatch`` CLI.

Services never import each other (import-linter checks it); they meet on
zenoh key expressions (:mod:`shared.contract.keys`). Only :mod:`services.cli` knows
them all.
"""
