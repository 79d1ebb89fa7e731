"""Acquisition: CAN frames in, 1 kHz samples out on zenoh; stop decisions back to CAN."""
