"""Code every boltwatch service uses: configuration, message contracts and
codecs, zenoh and CAN helpers, and the paper's analytical model.

``shared`` never imports ``services`` (an import-linter contract checks it).
"""
