"""Graded tests: one folder per lab, run against any implementation (--impl)."""
