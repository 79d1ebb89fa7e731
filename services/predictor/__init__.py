"""Predictor: the paper's real-time stick-slip algorithm (Section 6) on live samples."""
