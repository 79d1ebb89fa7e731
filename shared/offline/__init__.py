"""After-the-fact work over recordings, for the command line's verbs.

- :mod:`.post_mortem` (the paper's figures of one recorded run: ``boltwatch inspect``)
- :mod:`.overlay` (several runs on one figure: ``boltwatch inspect --overlay``)
- :mod:`.report` (statistics per program: ``boltwatch report``)
- :mod:`.controller_import` (a tool controller's runs into recordings:
  ``boltwatch import``)
"""
