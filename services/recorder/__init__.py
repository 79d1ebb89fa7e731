"""Recorder: MCAP files per run, Rerun, and the machine-wear ledger."""
