"""Statistics per program (``boltwatch report``) and the quality alert.

- :mod:`.recorded_results`: the results and run summaries of recordings in a range
- :mod:`.capability`: mean, σ, Cp, Cpk of a figure against its window
- :mod:`.control_chart`: X̄/R and X̄/s charts in subgroups
- :mod:`.program_statistics`: every figure of a program, NOK Pareto, stop reasons, events
- :mod:`.report_figure`: the report's picture (matplotlib)
- :mod:`.report_page`: the self-contained HTML page and the terminal summary
- :mod:`.quality_report`: read, compute, draw, write (``boltwatch report``)
- :mod:`.quality_watch`: the live quality alert (rolling Cpk, NOK run and rate) on zenoh
"""
