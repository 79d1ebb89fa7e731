"""Controller runs into recordings (``boltwatch import``).

- :mod:`.controller_run`: a controller's JSON run read and checked
- :mod:`.controller_steps`: the controller's own result (steps, functions, verdict)
- :mod:`.controller_timing`: its clock
- :mod:`.controller_import`: a run replayed through the predictor core into recordings
  (its TighteningResult: :mod:`shared.quality.controller_result`)
- :mod:`.import_files`: a run's files written whole or not at all
"""
