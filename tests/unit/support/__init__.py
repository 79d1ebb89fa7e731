"""Tests of the test support: doubles that speak real protocols, a real PostgreSQL server."""
