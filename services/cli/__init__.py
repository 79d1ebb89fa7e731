"""The ``boltwatch`` command line: the one place that knows every service."""
