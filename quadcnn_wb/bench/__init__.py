"""Benchmark commands: they print figures; no timing is asserted in unit tests."""
